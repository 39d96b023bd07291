"""A/B timing of CAPT inference with the pointwise layers as matrix products (``perception/pointwise.py``,
the default) against the same layers as oneDNN 1x1 convolutions (``nn.Conv1d/2d.forward``).

The two are interleaved in rounds (ABBA order) in one process on the same clouds, so drift of a shared
machine's speed hits both alike. Per category: the median ``predict`` latency (ms per cloud, double
voting included) and the median forward pass alone, over ``--clouds`` test clouds x ``--rounds``.

    .venv/bin/python scripts/pointwise_ab_timing.py --categories laptop oven \
        --json benchmarks/pointwise_ab_timing.json
"""

from __future__ import annotations

import argparse
import statistics
import time
from pathlib import Path

import numpy as np
import torch
from torch import nn

from capt_env.commands.json_output import script_command, write_json
from perception import pointwise
from perception.checkpoints import default_checkpoint
from perception.data import CaptShardDataset
from perception.inference import ArticulationEstimator

MATMUL = (pointwise.PointwiseConv1d.forward, pointwise.PointwiseConv2d.forward)


def use_matmul(matmul: bool) -> None:
    """Switch every pointwise layer between its matrix product and nn.Conv1d/2d's convolution."""
    pointwise.PointwiseConv1d.forward = MATMUL[0] if matmul else nn.Conv1d.forward
    pointwise.PointwiseConv2d.forward = MATMUL[1] if matmul else nn.Conv2d.forward


def time_category(category: str, data_root: Path, clouds: int, rounds: int) -> dict[str, float | int]:
    """Median ``predict`` latency and forward-pass time (ms) of the shipped ``category`` model, matrix
    product vs convolution, interleaved over ``rounds`` on the first ``clouds`` test clouds."""
    est = ArticulationEstimator.from_checkpoint(default_checkpoint(category))
    ds = CaptShardDataset(data_root / category, "test", est.config.model, augment=False, max_samples=clouds)
    pts = []
    for i in range(len(ds)):
        s = ds.sample(i)
        pts.append(np.asarray(s.points, np.float64)[np.asarray(s.part_labels) >= 0])
    x = torch.randn(1, est.config.model.num_points, 3, generator=torch.Generator().manual_seed(0))
    predict: dict[bool, list[float]] = {True: [], False: []}
    forward: dict[bool, list[float]] = {True: [], False: []}
    for r in range(rounds):
        for matmul in ((True, False) if r % 2 == 0 else (False, True)):
            use_matmul(matmul)
            for c in pts[:3]:
                est.predict(c)
            predict[matmul] += [est.predict(c).latency_ms for c in pts]
            with torch.no_grad():
                for _ in range(len(pts)):
                    t0 = time.perf_counter()
                    est.model(x)
                    forward[matmul].append((time.perf_counter() - t0) * 1000.0)
    use_matmul(True)
    return {"predict_ms_matmul": statistics.median(predict[True]),
            "predict_ms_conv": statistics.median(predict[False]),
            "forward_ms_matmul": statistics.median(forward[True]),
            "forward_ms_conv": statistics.median(forward[False]), "calls_each": len(predict[True])}


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--categories", nargs="+",
                        default=["laptop", "oven", "washing_machine", "eyeglasses"])
    parser.add_argument("--data", type=Path, default=Path("data"), help="holds <category>/ datasets")
    parser.add_argument("--clouds", type=int, default=40)
    parser.add_argument("--rounds", type=int, default=6)
    parser.add_argument("--json", type=Path, default=None)
    args = parser.parse_args()
    if args.clouds < 1 or args.rounds < 2:
        parser.error("--clouds must be >= 1 and --rounds >= 2")
    results = {}
    for cat in args.categories:
        if not (args.data / cat).is_dir():
            parser.error(f"no dataset for {cat} under {args.data} (capt generate it first)")
        r = time_category(cat, args.data, args.clouds, args.rounds)
        results[cat] = r
        print(f"{cat}: predict {r['predict_ms_matmul']:.1f} ms (matmul) vs {r['predict_ms_conv']:.1f} ms "
              f"(conv); forward {r['forward_ms_matmul']:.1f} vs {r['forward_ms_conv']:.1f} ms; "
              f"{r['calls_each']} calls each")
    write_json(args.json, {"threads": torch.get_num_threads(), "results": results}, script_command())


if __name__ == "__main__":
    main()
