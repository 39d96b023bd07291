"""Points fed to the network against accuracy and time: a shipped checkpoint run with fewer points than
it was trained with, on the validation split.

The network takes any number of points (its attention is n x n); ``ArticulationEstimator`` resamples
every cloud to ``config.model.num_points``. This script replaces that number and scores the same
clouds at each count, with the median ``predict`` time, to show where accuracy holds. Used to decide
whether fewer points could buy speed (the shipped models keep the count they were trained with).

    OMP_NUM_THREADS=1 .venv/bin/python scripts/points_accuracy_curve.py --data /tmp/capt_val \\
        --categories laptop cabinet_door drawer_cabinet --json benchmarks/points_accuracy_curve.json
"""

from __future__ import annotations

import argparse
import statistics
from dataclasses import replace
from pathlib import Path

import numpy as np

from capt_common.json_report import script_command, write_json
from perception.checkpoint import build_model, load_checkpoint
from perception.checkpoints import default_checkpoint
from perception.data import CaptShardDataset
from perception.evaluation import score_sample
from perception.inference import ArticulationEstimator
from perception.metrics import summarise


def curve(category: str, data: Path, split: str, counts: list[int]) -> dict[int, dict]:
    """Per point count: the summary metrics of :func:`perception.metrics.summarise` and the median
    ms per cloud of the shipped ``category`` model on ``split``."""
    ckpt = load_checkpoint(default_checkpoint(category))
    base = ckpt.config.model
    ds = CaptShardDataset(data / category, split, base, augment=False)
    samples = [ds.posed(i) for i in range(len(ds))]
    clouds = [s.object_points() for s in samples]
    out = {}
    for n in counts:
        config = replace(ckpt.config, model=replace(base, num_points=n))
        est = ArticulationEstimator(build_model(ckpt, "cpu"), config, ckpt.voting_window, category)
        for c in clouds[:3]:
            est.predict(c)
        results, times = [], []
        for s, c in zip(samples, clouds, strict=True):
            pred = est.predict(c)
            times.append(pred.latency_ms)
            results.append(score_sample(pred, s, f"n={n}", base.has_segmentation))
        out[n] = {"summary": summarise(results), "ms_median": statistics.median(times)}
    return out


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0],
                                     formatter_class=argparse.ArgumentDefaultsHelpFormatter)
    parser.add_argument("--data", type=Path, required=True, help="holds <category>/ datasets")
    parser.add_argument("--split", default="val")
    parser.add_argument("--categories", nargs="+", default=["laptop", "cabinet_door", "drawer_cabinet"])
    parser.add_argument("--counts", type=int, nargs="+", default=[128, 256, 384, 512])
    parser.add_argument("--json", type=Path, default=None)
    args = parser.parse_args()
    results = {}
    for cat in args.categories:
        results[cat] = curve(cat, args.data, args.split, args.counts)
        for n, r in results[cat].items():
            m = r["summary"]
            print(f"{cat} n={n}: {r['ms_median']:.1f} ms, mIoU {m['miou']:.3f}, direction "
                  f"{np.mean(m['dir_med']):.2f} deg, state {np.mean(m['state_med']):.3f}", flush=True)
    write_json(args.json, {"split": args.split, "results": results}, script_command())


if __name__ == "__main__":
    main()
