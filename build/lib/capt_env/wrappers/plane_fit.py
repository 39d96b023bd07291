"""Seeded RANSAC plane fitting of point clouds (metres): the table under an object, a door's face."""

from __future__ import annotations

import numpy as np


def ransac_plane(points: np.ndarray, iterations: int, threshold: float, seed: int,
                 max_tilt: float | None = None) -> tuple[np.ndarray, np.ndarray | None]:
    """The plane, among ``iterations`` planes through three of the ``points`` (N, 3) drawn with
    ``seed`` (deterministic), that holds the most of them within ``threshold`` m: its inlier mask
    (N,) and its unit normal (3,) (sign arbitrary).

    With ``max_tilt`` (radians) only planes within that angle of horizontal (world +z up) count.
    (all-False mask, None) when no plane is found (fewer than 3 points, or every draw degenerate or
    too tilted).
    """
    best = np.zeros(len(points), dtype=bool)
    best_normal = None
    if len(points) < 3:
        return best, None
    rng = np.random.default_rng(seed)
    min_abs_z = None if max_tilt is None else float(np.cos(max_tilt))
    for _ in range(iterations):
        a, b, c = points[rng.choice(len(points), 3, replace=False)]
        normal = np.cross(b - a, c - a)
        norm = float(np.linalg.norm(normal))
        if norm < 1e-9:
            continue
        normal = normal / norm
        if min_abs_z is not None and abs(normal[2]) < min_abs_z:
            continue
        inliers = np.abs((points - a) @ normal) < threshold
        if inliers.sum() > best.sum():
            best, best_normal = inliers, normal
    return best, best_normal
