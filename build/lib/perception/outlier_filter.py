"""Statistical outlier removal for input clouds: drop the stray returns a depth camera adds before the
network sees the cloud.

A point's score is its mean distance to its ``neighbours`` nearest other points (metres, or whatever unit
the cloud is in; the test is scale-free). A point is kept when its score is at most
``median + std_ratio * spread`` of all scores: the classic statistical filter (as in PCL and Open3D),
with robust statistics in place of the mean and standard deviation so that many stray points do not
widen the threshold that is meant to find them. ``spread`` is 1.4826 times the median absolute deviation
of the scores, but at least ``MIN_SPREAD`` times their median: on a near-regular grid (a depth image's
pixels on a flat face) the deviation is close to zero, and without the floor the grid's own edges would
be cut. On the rendered test clouds the deviation term is 0.15-0.7 of the median, above the floor.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
import torch

MAD_TO_STD = 1.4826  # a normal distribution's standard deviation over its median absolute deviation
MIN_SPREAD = 0.25  # the spread's floor, as a fraction of the median score


@dataclass(frozen=True)
class OutlierFilter:
    """``neighbours``: how many nearest points score each point (>= 1); ``std_ratio``: how many robust
    standard deviations above the median score a kept point may lie (> 0)."""

    neighbours: int = 8
    std_ratio: float = 3.0

    def __post_init__(self) -> None:
        if isinstance(self.neighbours, bool) or not isinstance(self.neighbours, int) or self.neighbours < 1:
            raise ValueError(f"neighbours must be an integer >= 1, got {self.neighbours!r}")
        if not (math.isfinite(self.std_ratio) and self.std_ratio > 0):
            raise ValueError(f"std_ratio must be a finite number > 0, got {self.std_ratio!r}")


def mean_neighbour_distance(points: np.ndarray, neighbours: int, chunk: int = 2048) -> np.ndarray:
    """(N,) mean Euclidean distance of each point of ``points`` (N, 3) to its ``neighbours`` nearest other
    points (fewer when the cloud has fewer)."""
    pts = torch.as_tensor(np.asarray(points), dtype=torch.float32)
    k = min(neighbours, len(pts) - 1)
    if k < 1:
        return np.zeros(len(pts))
    out = np.empty(len(pts))
    for s in range(0, len(pts), chunk):
        d = torch.cdist(pts[s:s + chunk], pts)
        # the k + 1 smallest include the point itself at distance 0
        out[s:s + chunk] = d.topk(k + 1, dim=1, largest=False).values[:, 1:].mean(dim=1).double().numpy()
    return out


def inlier_mask(points: np.ndarray, filt: OutlierFilter) -> np.ndarray:
    """(N,) bool: True for the points ``filt`` keeps (see the module docstring)."""
    score = mean_neighbour_distance(points, filt.neighbours)
    med = float(np.median(score))
    mad = float(np.median(np.abs(score - med)))
    spread = max(MAD_TO_STD * mad, MIN_SPREAD * med)
    return score <= med + filt.std_ratio * spread
