"""Time CAPT inference (network, double voting, segmentation back onto the cloud) on stored clouds,
one at a time and in batches, on the CPU or a GPU. Simulator-free: it imports ``perception`` only,
so it runs on a machine with PyTorch alone (a lent GPU); ``capt bench`` times the whole task.

    python scripts/time_predict.py perception/checkpoints/laptop.pt --data data/cross/laptop \
        --split val --device cuda --json timing.json
"""

from __future__ import annotations

import argparse
import json
import platform
import statistics
import time
from pathlib import Path

import numpy as np
import torch

from perception.data import load_split
from perception.inference import ArticulationEstimator


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("checkpoint", type=Path)
    parser.add_argument("--data", type=Path, required=True, help="a shard directory")
    parser.add_argument("--split", default="val")
    parser.add_argument("--device", default="cpu")
    parser.add_argument("--clouds", type=int, default=100)
    parser.add_argument("--batch", type=int, default=16)
    parser.add_argument("--json", type=Path, default=None)
    args = parser.parse_args()
    arrays = load_split(args.data, args.split)
    clouds = [np.asarray(p[lab >= 0], np.float64) for p, lab in
              zip(arrays["points"][:args.clouds], arrays["part_labels"][:args.clouds], strict=True)]
    estimator = ArticulationEstimator.from_checkpoint(args.checkpoint, device=args.device)
    for cloud in clouds[:5]:  # warm-up (CUDA context, kernels, allocator)
        estimator.predict(cloud)
    single = []
    for cloud in clouds:
        t0 = time.perf_counter()
        estimator.predict(cloud)
        single.append(1e3 * (time.perf_counter() - t0))
    batched = []
    for i in range(0, len(clouds) - args.batch + 1, args.batch):
        t0 = time.perf_counter()
        estimator.predict_batch(clouds[i:i + args.batch])
        batched.append(1e3 * (time.perf_counter() - t0) / args.batch)
    report = {
        "command": "python " + " ".join(["scripts/time_predict.py", str(args.checkpoint), "--data",
                                         str(args.data), "--split", args.split, "--device", args.device]),
        "machine": {"platform": platform.platform(), "torch": torch.__version__,
                    "device": torch.cuda.get_device_name() if args.device.startswith("cuda")
                    else platform.processor() or "cpu", "torch_threads": torch.get_num_threads()},
        "clouds": len(clouds), "points_per_cloud_median": int(np.median([len(c) for c in clouds])),
        "ms_per_cloud_single_median": round(statistics.median(single), 2),
        "batch": args.batch,
        "ms_per_cloud_batched_median": round(statistics.median(batched), 2) if batched else None,
    }
    print(json.dumps(report, indent=2))
    if args.json is not None:
        args.json.write_text(json.dumps(report, indent=2))


if __name__ == "__main__":
    main()
