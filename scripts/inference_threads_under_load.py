"""CAPT ``predict`` time per cloud by torch thread count, on an idle machine and beside a busy process.

Each condition is timed in interleaved rounds on the same test clouds of one category. "busy" starts a
second process that keeps one core fully used (a pure-Python loop), as a simulator does beside
perception; "busy_torch" one that runs torch matrix products at torch's default thread count, as a
second rollout worker's inference or a training job does. Threads are set per call with
``ArticulationEstimator(num_threads=...)``; the default estimator uses
:data:`perception.inference.DEFAULT_CPU_THREADS`.

    .venv/bin/python scripts/inference_threads_under_load.py --data /tmp/capt_data \\
        --json benchmarks/inference_threads.json
"""

from __future__ import annotations

import argparse
import multiprocessing as mp
import os
import statistics
import time
from pathlib import Path
from typing import Any

import numpy as np

from capt_common.json_report import script_command, write_json


def _spin(stop: Any) -> None:
    """Keep one core busy with plain Python."""
    x = 0
    while not stop.is_set():
        for _ in range(100_000):
            x += 1


def _spin_torch(stop: Any) -> None:
    """Keep the cores busy with torch at its default thread count (another process's inference or
    training)."""
    import torch

    a = torch.randn(256, 256)
    while not stop.is_set():
        for _ in range(20):
            a = torch.tanh(a @ a)


def _clouds(data: Path, category: str, count: int) -> list[np.ndarray]:
    from perception.checkpoints import default_checkpoint
    from perception.data import CaptShardDataset
    from perception.inference import ArticulationEstimator

    cfg = ArticulationEstimator.from_checkpoint(default_checkpoint(category)).config.model
    ds = CaptShardDataset(data / category, "test", cfg, augment=False, max_samples=count)
    return [ds.sample(i).object_points() for i in range(len(ds))]


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0],
                                     formatter_class=argparse.ArgumentDefaultsHelpFormatter)
    parser.add_argument("--data", type=Path, required=True, help="holds <category>/ test splits")
    parser.add_argument("--category", default="laptop")
    parser.add_argument("--clouds", type=int, default=30)
    parser.add_argument("--rounds", type=int, default=4)
    parser.add_argument("--threads", type=int, nargs="+", default=[1, os.cpu_count() or 2])
    parser.add_argument("--json", type=Path, default=None)
    args = parser.parse_args()

    import torch

    from perception.checkpoints import default_checkpoint
    from perception.inference import ArticulationEstimator

    clouds = _clouds(args.data, args.category, args.clouds)
    estimators = {n: ArticulationEstimator.from_checkpoint(default_checkpoint(args.category), num_threads=n)
                  for n in args.threads}
    times: dict[str, list[float]] = {}
    ctx = mp.get_context("spawn")  # a forked child of a process that ran torch threads can hang
    stop = ctx.Event()
    loads = {"idle": None, "busy": _spin, "busy_torch": _spin_torch}
    for load, target in loads.items():
        stop.clear()
        spinner = ctx.Process(target=target, args=(stop,), daemon=True) if target is not None else None
        if spinner is not None:
            spinner.start()
            time.sleep(3.0)  # the spawned child imports before it loads the core
        try:
            for r in range(args.rounds):
                order = args.threads if r % 2 == 0 else list(reversed(args.threads))
                for n in order:
                    est = estimators[n]
                    for c in clouds[:3]:
                        est.predict(c)
                    calls = times.setdefault(f"{load}_threads{n}", [])
                    calls.extend(est.predict(c).latency_ms for c in clouds)
        finally:
            if spinner is not None:
                stop.set()
                spinner.join()
    medians = {k: statistics.median(v) for k, v in times.items()}
    for k, v in medians.items():
        print(f"{k}: {v:.1f} ms per cloud (median of {len(times[k])})")
    write_json(args.json, {"category": args.category, "torch_default_threads": torch.get_num_threads(),
                           "median_ms": medians, "calls": {k: len(v) for k, v in times.items()}},
               script_command())


if __name__ == "__main__":
    main()
