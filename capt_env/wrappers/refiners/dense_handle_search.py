"""Refiner ``dense_handle_search``: look for handles among all isolated object points.

Geometric reason: a handle is a handful of the points fed to the network (1,024 of thousands), so
one random draw keeps it and the next loses it, and the grasp point then falls back to the part's
far edge. All isolated points show it every time. The fewest points of a handle scale with the
density (K / M), so a handle is the same share of the cloud and scattered strays stay too few.
Must not fire: when there are no dense points, or they are no denser than the network's input.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import ClassVar

import numpy as np

from capt_env.wrappers.refiners.draft import MIN_HANDLE_POINTS, Draft


@dataclass(frozen=True)
class DenseHandleSearchConfig:
    """No settings: the handle's minimum size scales with the density, from ``MIN_HANDLE_POINTS``."""

    def validate(self) -> None:
        pass


def handle_search_points(points: np.ndarray, dense_points: np.ndarray | None) -> tuple[np.ndarray, int]:
    """(points to look for handles among, the fewest points of a handle): ``dense_points`` (K, 3)
    when given and denser than ``points`` (M, 3), with the minimum scaled by K / M so a handle is the
    same share of the cloud (3 of the model's input), else ``points`` and 3. Metres."""
    if dense_points is None or len(dense_points) <= len(points):
        return points, MIN_HANDLE_POINTS
    dense = np.asarray(dense_points, dtype=np.float64)
    return dense, max(MIN_HANDLE_POINTS, round(MIN_HANDLE_POINTS * len(dense) / len(points)))


class DenseHandleSearch:
    """Point the draft's handle search (``handle_cloud``, ``handle_min_points``) at the dense points."""

    name: ClassVar[str] = "dense_handle_search"

    def __init__(self, config: DenseHandleSearchConfig | None = None) -> None:
        self.config = config or DenseHandleSearchConfig()

    def refine(self, draft: Draft) -> bool:
        cloud, fewest = handle_search_points(draft.points, draft.dense_points)
        if cloud is draft.points:
            return False
        draft.handle_cloud, draft.handle_min_points = cloud, fewest
        return True
