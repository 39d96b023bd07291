"""Cut the object's points out of a world-frame cloud, with labels (simulation) or without (geometry).

``segmentation``: keep points whose part label is >= 0. ``geometric`` (what a real robot can do):
1. drop background points (``w == 0`` in ManiSkill's xyzw) and crop to the workspace box;
2. fit the table plane by seeded RANSAC and drop everything below ``plane + threshold + margin``;
3. drop points within a margin of the robot's collision shapes at its current link poses;
4. drop statistical outliers (mean distance to k nearest neighbours > mean + s * std).
:func:`isolation_quality` scores a mask against the simulator's part labels.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any

import numpy as np
from scipy.spatial import cKDTree

from capt_env.wrappers.config import IsolationConfig
from capt_env.wrappers.plane_fit import ransac_plane
from capt_env.wrappers.robot_filter import RobotPointFilter


@dataclass(frozen=True)
class Plane:
    """``normal`` (3,) unit, pointing up (+z side); points x with ``normal @ x + offset = 0``."""

    normal: np.ndarray
    offset: float

    def height(self, points: np.ndarray) -> np.ndarray:
        """Signed distance (N,) of points (N, 3) above the plane, metres."""
        return points @ self.normal + self.offset


def fit_plane_ransac(points: np.ndarray, iterations: int, threshold: float, seed: int,
                     max_tilt: float = 0.35) -> Plane | None:
    """Dominant near-horizontal plane of ``points`` (N, 3), metres, by RANSAC plus a least-squares refit.

    Only planes within ``max_tilt`` rad of horizontal are considered (a table, not a cabinet wall).
    Returns None if no plane has at least 3 inliers.
    """
    mask, normal = ransac_plane(points, iterations, threshold, seed, max_tilt=max_tilt)
    if normal is None or mask.sum() < 3:
        return None
    inliers = points[mask]
    centre = inliers.mean(axis=0)
    _, _, vt = np.linalg.svd(inliers - centre, full_matrices=False)
    normal = vt[-1] if abs(vt[-1] @ normal) > 0.9 else normal
    if normal[2] < 0:
        normal = -normal
    return Plane(normal=normal, offset=float(-normal @ centre))


def statistical_inliers(points: np.ndarray, k: int, std_ratio: float) -> np.ndarray:
    """(N,) bool: mean distance to the ``k`` nearest neighbours <= mean + ``std_ratio`` * std."""
    if len(points) <= k:
        return np.ones(len(points), dtype=bool)
    dist, _ = cKDTree(points).query(points, k=k + 1)
    mean_d = dist[:, 1:].mean(axis=1)
    return mean_d <= mean_d.mean() + std_ratio * mean_d.std()


def geometric_mask(xyzw: np.ndarray, cfg: IsolationConfig, robot: RobotPointFilter | None) -> np.ndarray:
    """(N,) bool mask of object points of a world-frame cloud ``xyzw`` (N, 4) or (N, 3), no labels."""
    pts = np.asarray(xyzw[:, :3], dtype=np.float64)
    keep = np.isfinite(pts).all(axis=1)
    if xyzw.shape[1] == 4:
        keep &= xyzw[:, 3] > 0
    lo, hi = np.asarray(cfg.workspace_min), np.asarray(cfg.workspace_max)
    keep &= (pts >= lo).all(axis=1) & (pts <= hi).all(axis=1)
    idx = np.flatnonzero(keep)
    plane = fit_plane_ransac(pts[idx], cfg.plane_iterations, cfg.plane_threshold, cfg.seed)
    if plane is not None:
        idx = idx[plane.height(pts[idx]) > cfg.plane_threshold + cfg.plane_margin]
    if robot is not None and len(idx):
        idx = idx[~robot.mask(pts[idx], cfg.robot_margin)]
    if len(idx):
        idx = idx[statistical_inliers(pts[idx], cfg.outlier_k, cfg.outlier_std)]
    mask = np.zeros(len(pts), dtype=bool)
    mask[idx] = True
    return mask


def segmentation_mask(part_label: np.ndarray) -> np.ndarray:
    """(N,) bool: points whose simulator part label is >= 0 (on the object)."""
    return np.asarray(part_label).reshape(-1) >= 0


def isolate(xyzw: np.ndarray, part_label: np.ndarray | None, cfg: IsolationConfig,
            robot: RobotPointFilter | None) -> np.ndarray:
    """(N,) bool object mask of a cloud by ``cfg.mode``; ``segmentation`` needs ``part_label`` (N,)."""
    if cfg.mode == "segmentation":
        if part_label is None:
            raise ValueError("segmentation isolation needs per-point part labels")
        return segmentation_mask(part_label)
    return geometric_mask(xyzw, cfg, robot)


@dataclass(frozen=True)
class IsolationQuality:
    """``recall``: share of true object points kept; ``precision``: share of kept points on the object;
    ``non_object_share`` = 1 - precision; counts of kept and true object points."""

    recall: float
    precision: float
    non_object_share: float
    kept: int
    object_points: int


def isolation_quality(mask: np.ndarray, part_label: np.ndarray) -> IsolationQuality:
    """Score a kept-points ``mask`` (N,) against simulator part labels (N,) (-1 = not the object)."""
    truth = segmentation_mask(part_label)
    kept = int(mask.sum())
    hit = int((mask & truth).sum())
    recall = hit / max(int(truth.sum()), 1)
    precision = hit / kept if kept else 0.0
    return IsolationQuality(recall, precision, 1.0 - precision, kept, int(truth.sum()))


def camera_viewpoint(obs: Any) -> np.ndarray | None:
    """The mean position (3,) of the cameras in a pointcloud observation (``sensor_param``'s
    ``cam2world_gl`` of each, first sub-scene), world frame, metres; None without camera
    parameters."""
    params = obs.get("sensor_param") if isinstance(obs, dict) else None
    if not params:
        return None
    eyes = []
    for cam in params.values():
        pose = cam["cam2world_gl"]
        pose = pose.cpu().numpy() if hasattr(pose, "cpu") else np.asarray(pose)
        eyes.append(np.asarray(pose, dtype=np.float64).reshape(-1, 4, 4)[0, :3, 3])
    return np.mean(eyes, axis=0)
