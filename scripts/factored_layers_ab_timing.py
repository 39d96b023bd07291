"""A/B timing of CAPT inference with the factored layers (session 30) against the forms they replaced.

Factored (the default in ``perception/``): the neighbour embedding applies its linear map to the n
points before gathering the k neighbours; the heads add the global feature's term once per cloud
instead of multiplying its broadcast copy; the kNN and the nearest-fed-point labels rank by
``|r|^2 - 2 q . r`` with no square root, and only the points not fed to the network are looked up.
Concatenated (the session-29 forms, kept here as the reference): the (2C, n, k) edge tensor and the
(C + G, n) head input are built and multiplied; ``torch.cdist`` for both searches.

The two are interleaved in rounds (ABBA order) in one process on the same clouds, so drift of a shared
machine's speed hits both alike. Per category: the median ``predict`` latency (ms per cloud, double
voting included) and the median forward pass alone, over ``--clouds`` test clouds x ``--rounds``.

    .venv/bin/python scripts/factored_layers_ab_timing.py --json benchmarks/factored_layers_ab_timing.json
"""

from __future__ import annotations

import argparse
import statistics
import time
from collections.abc import Callable
from pathlib import Path
from typing import Any

import numpy as np
import torch
from torch import nn

from capt_env.commands.json_output import script_command, write_json
from perception import encoder, heads, inference
from perception.checkpoints import default_checkpoint
from perception.data import CaptShardDataset
from perception.inference import ArticulationEstimator


def concat_neighbour_forward(self: encoder.NeighbourEmbedding, feat: torch.Tensor,
                             idx: torch.Tensor) -> torch.Tensor:
    """Reference: the (f_j - f_i, f_i) edge tensor (B, 2C, n, k) built, then the LBR, then max over k."""
    neigh = encoder.gather_neighbours(feat, idx)
    centre = feat.unsqueeze(-1).expand_as(neigh)
    return self.mlp(torch.cat([neigh - centre, centre], dim=1)).amax(dim=-1)


def concat_run_with_global(mlp: nn.Sequential, per_point: torch.Tensor,
                           global_feat: torch.Tensor) -> torch.Tensor:
    """Reference: ``mlp`` on the (B, C + G, n) concatenation of per-point and broadcast global features."""
    n = per_point.shape[1]
    return mlp(torch.cat([per_point.transpose(1, 2), global_feat.unsqueeze(-1).expand(-1, -1, n)], dim=1))


def cdist_knn_indices(xyz: torch.Tensor, k: int) -> torch.Tensor:
    """Reference: k nearest neighbours by ``torch.cdist`` distances."""
    return torch.cdist(xyz, xyz).topk(k, dim=-1, largest=False).indices


def cdist_labels_for_all_points(points: np.ndarray, fed: np.ndarray, fed_labels: np.ndarray) -> np.ndarray:
    """Reference: every point (fed or not) takes the label of its nearest fed point by ``torch.cdist``."""
    ref = torch.as_tensor(points[fed], dtype=torch.float32)
    query = torch.as_tensor(points, dtype=torch.float32)
    return fed_labels[torch.cdist(query, ref).argmin(dim=1).numpy()]


FACTORED: dict[str, Any] = {"neighbour": encoder.NeighbourEmbedding.forward, "heads": heads._run_with_global,
                            "knn": encoder.knn_indices, "labels": inference.labels_for_all_points}
CONCATENATED: dict[str, Any] = {"neighbour": concat_neighbour_forward, "heads": concat_run_with_global,
                                "knn": cdist_knn_indices, "labels": cdist_labels_for_all_points}


def use_factored(factored: bool) -> None:
    """Switch the encoder, heads and label lookup between the factored forms and the references."""
    forms = FACTORED if factored else CONCATENATED
    encoder.NeighbourEmbedding.forward = forms["neighbour"]
    heads._run_with_global = forms["heads"]
    encoder.knn_indices = forms["knn"]
    inference.labels_for_all_points = forms["labels"]


def _times_ms(calls: list[Callable[[], object]]) -> list[float]:
    out = []
    for call in calls:
        t0 = time.perf_counter()
        call()
        out.append((time.perf_counter() - t0) * 1000.0)
    return out


def time_category(category: str, data_root: Path, clouds: int, rounds: int) -> dict[str, float | int]:
    """Median ``predict`` latency and forward-pass time (ms) of the shipped ``category`` model, factored
    vs concatenated, interleaved over ``rounds`` on the first ``clouds`` test clouds."""
    est = ArticulationEstimator.from_checkpoint(default_checkpoint(category))
    ds = CaptShardDataset(data_root / category, "test", est.config.model, augment=False, max_samples=clouds)
    pts = []
    for i in range(len(ds)):
        s = ds.sample(i)
        pts.append(np.asarray(s.points, np.float64)[np.asarray(s.part_labels) >= 0])
    x = torch.randn(1, est.config.model.num_points, 3, generator=torch.Generator().manual_seed(0))
    predict: dict[bool, list[float]] = {True: [], False: []}
    forward: dict[bool, list[float]] = {True: [], False: []}
    try:
        for r in range(rounds):
            for factored in ((True, False) if r % 2 == 0 else (False, True)):
                use_factored(factored)
                for c in pts[:3]:
                    est.predict(c)
                predict[factored] += [est.predict(c).latency_ms for c in pts]
                with torch.no_grad():
                    forward[factored] += _times_ms([lambda: est.model(x)] * len(pts))
    finally:
        use_factored(True)
    return {"predict_ms_factored": statistics.median(predict[True]),
            "predict_ms_concatenated": statistics.median(predict[False]),
            "forward_ms_factored": statistics.median(forward[True]),
            "forward_ms_concatenated": statistics.median(forward[False]), "calls_each": len(predict[True])}


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
        print(f"{cat}: predict {r['predict_ms_factored']:.1f} ms (factored) vs "
              f"{r['predict_ms_concatenated']:.1f} ms (concatenated); forward {r['forward_ms_factored']:.1f} "
              f"vs {r['forward_ms_concatenated']:.1f} ms; {r['calls_each']} calls each")
    write_json(args.json, {"threads": torch.get_num_threads(), "results": results}, script_command())


if __name__ == "__main__":
    main()
