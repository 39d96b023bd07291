"""Pack training clouds small enough to travel: each cloud keeps ``--points`` of its object points
(drawn at random, without replacement when it has that many), coordinates as float16 (0.5 mm at 1 m)
and part labels as int8, in the ordinary shard layout (:mod:`perception.data`), compressed.

For training on a machine the full datasets cannot be copied to (a lent GPU with a 64 MiB transfer
limit). A model trained on packed clouds samples ``model.num_points`` of the packed points each epoch,
so keep ``--points`` at or above it. Background points are dropped (training drops them anyway).

    python scripts/pack_training_clouds.py data/cross/laptop ... --out runs/device_pack \
        --points 640 --max-train 700 --max-val 50
"""

from __future__ import annotations

import argparse
import json
from pathlib import Path

import numpy as np

from perception.data import SAMPLE_KEYS, load_split


def pack_split(arrays: dict[str, np.ndarray], points: int, limit: int | None,
               rng: np.random.Generator) -> dict[str, np.ndarray]:
    """The first ``limit`` samples of a split, each cut to ``points`` object points."""
    n = len(arrays["points"]) if limit is None else min(limit, len(arrays["points"]))
    pts = np.empty((n, points, 3), np.float16)
    labels = np.empty((n, points), np.int8)
    for i in range(n):
        obj = np.flatnonzero(arrays["part_labels"][i] >= 0)
        if len(obj) == 0:
            raise ValueError(f"sample {i} has no object points")
        pick = obj[rng.choice(len(obj), size=points, replace=len(obj) < points)]
        pts[i] = arrays["points"][i][pick]
        labels[i] = arrays["part_labels"][i][pick]
    out = {k: arrays[k][:n] for k in SAMPLE_KEYS}
    out["points"], out["part_labels"] = pts, labels
    return out


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("data", nargs="+", type=Path, help="shard directories (one per dataset)")
    parser.add_argument("--out", type=Path, required=True, help="directory; one packed dataset per input")
    parser.add_argument("--points", type=int, default=640, help="object points kept per cloud")
    parser.add_argument("--max-train", type=int, default=None, help="train samples kept per dataset")
    parser.add_argument("--max-val", type=int, default=None, help="validation samples kept per dataset")
    parser.add_argument("--seed", type=int, default=0)
    args = parser.parse_args()
    rng = np.random.default_rng(args.seed)
    for src in args.data:
        dst = args.out / f"{src.parent.name}_{src.name}"
        counts = {}
        for split, limit in (("train", args.max_train), ("val", args.max_val)):
            packed = pack_split(load_split(src, split), args.points, limit, rng)
            (dst / split).mkdir(parents=True, exist_ok=True)
            np.savez_compressed(dst / split / "shard_00000.npz", **packed)
            counts[split] = len(packed["points"])
        (dst / "manifest.json").write_text(json.dumps(
            {"format": "capt-env-shards/1", "packed_from": str(src), "points": args.points,
             "counts": counts}, indent=2))
        size = sum(f.stat().st_size for f in dst.rglob("*.npz")) / 2**20
        print(f"{src} -> {dst}: {counts}, {size:.1f} MiB")


if __name__ == "__main__":
    main()
