"""A/B timing of CAPT inference with the factored layers (session 30) against the forms they replaced.

Factored (the default in ``perception/``): the neighbour embedding applies its linear map to the n
points before gathering the k neighbours; the heads add the global feature's term once per cloud
instead of multiplying its broadcast copy; the kNN and the nearest-fed-point labels rank by
``|r|^2 - 2 q . r`` with no square root, and only the points not fed to the network are looked up.
Concatenated (the session-29 forms, kept here as the reference): the (2C, n, k) edge tensor and the
(C + G, n) head input are built and multiplied; ``torch.cdist`` for both searches.

Timed interleaved, in ABBA rounds in one process on the same test clouds, by
:mod:`perception.interleaved_timing` (median ``predict`` and forward-pass times per category).

    .venv/bin/python scripts/factored_layers_ab_timing.py --json benchmarks/factored_layers_ab_timing.json
"""

from __future__ import annotations

from typing import Any

import numpy as np
import torch
from torch import nn

from perception import encoder, heads, inference, interleaved_timing


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


if __name__ == "__main__":
    interleaved_timing.main(__doc__.splitlines()[0], use_factored, ("factored", "concatenated"))
