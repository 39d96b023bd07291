"""Interleaved A/B timing of a shipped model's inference under two implementations of the same layers.

A ``switch(on: bool)`` installs implementation A (``True``) or B (``False``). Both are timed in one
process on the same test clouds, in ABBA rounds, so drift of a shared machine's speed hits both alike.
Reported per category: the median ``predict`` latency (ms per cloud, double voting included) and the
median forward pass alone (ms, one random cloud of ``num_points``), each over clouds x rounds calls.
Used by ``scripts/pointwise_ab_timing.py`` and ``scripts/factored_layers_ab_timing.py``.
"""

from __future__ import annotations

import argparse
import statistics
import time
from collections.abc import Callable
from pathlib import Path

import torch

from capt_common.json_report import script_command, write_json
from perception.checkpoints import default_checkpoint
from perception.data import CaptShardDataset
from perception.inference import ArticulationEstimator

PAPER_CATEGORIES = ["laptop", "oven", "washing_machine", "eyeglasses"]


def time_category(category: str, data_root: Path, clouds: int, rounds: int, switch: Callable[[bool], None],
                  names: tuple[str, str]) -> dict[str, float | int]:
    """Median ``predict`` and forward-pass times (ms) of the shipped ``category`` model under A and B,
    keyed ``predict_ms_<name>`` / ``forward_ms_<name>``; A is switched back on at the end."""
    est = ArticulationEstimator.from_checkpoint(default_checkpoint(category))
    ds = CaptShardDataset(data_root / category, "test", est.config.model, augment=False, max_samples=clouds)
    pts = []
    for i in range(len(ds)):
        s = ds.sample(i)
        pts.append(s.object_points())
    x = torch.randn(1, est.config.model.num_points, 3, generator=torch.Generator().manual_seed(0))
    predict: dict[bool, list[float]] = {True: [], False: []}
    forward: dict[bool, list[float]] = {True: [], False: []}
    try:
        for r in range(rounds):
            for on in ((True, False) if r % 2 == 0 else (False, True)):
                switch(on)
                for c in pts[:3]:
                    est.predict(c)
                predict[on] += [est.predict(c).latency_ms for c in pts]
                with torch.no_grad():
                    for _ in range(len(pts)):
                        t0 = time.perf_counter()
                        est.model(x)
                        forward[on].append((time.perf_counter() - t0) * 1000.0)
    finally:
        switch(True)
    out: dict[str, float | int] = {}
    for on, name in zip((True, False), names, strict=True):
        out[f"predict_ms_{name}"] = statistics.median(predict[on])
    for on, name in zip((True, False), names, strict=True):
        out[f"forward_ms_{name}"] = statistics.median(forward[on])
    out["calls_each"] = len(predict[True])
    return out


def main(description: str, switch: Callable[[bool], None], names: tuple[str, str]) -> None:
    """Command line of an A/B timing script: ``--categories``, ``--data``, ``--clouds``, ``--rounds``,
    ``--json``; prints one line per category and writes the results with the command line."""
    parser = argparse.ArgumentParser(description=description)
    parser.add_argument("--categories", nargs="+", default=PAPER_CATEGORIES)
    parser.add_argument("--data", type=Path, default=Path("data"), help="holds <category>/ datasets")
    parser.add_argument("--clouds", type=int, default=40)
    parser.add_argument("--rounds", type=int, default=6)
    parser.add_argument("--json", type=Path, default=None)
    args = parser.parse_args()
    if args.clouds < 1 or args.rounds < 2:
        parser.error("--clouds must be >= 1 and --rounds >= 2")
    results = {}
    a, b = names
    for cat in args.categories:
        if not (args.data / cat).is_dir():
            parser.error(f"no dataset for {cat} under {args.data} (capt generate it first)")
        r = time_category(cat, args.data, args.clouds, args.rounds, switch, names)
        results[cat] = r
        print(f"{cat}: predict {r[f'predict_ms_{a}']:.1f} ms ({a}) vs {r[f'predict_ms_{b}']:.1f} ms ({b}); "
              f"forward {r[f'forward_ms_{a}']:.1f} vs {r[f'forward_ms_{b}']:.1f} ms; "
              f"{r['calls_each']} calls each")
    write_json(args.json, {"threads": torch.get_num_threads(), "results": results}, script_command())
