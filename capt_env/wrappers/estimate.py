"""The joint-axis estimate of the target joint, world frame, as the observation and the agents see it.

Also the two canonical choices an estimate needs: the pivot (the point of the axis closest to the
grasp point) and the grasp point of a moving part: its handle when one stands off the part's plane,
else the far edge from a revolute axis or the front-most points along a prismatic axis.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

JOINT_TYPES: tuple[str, ...] = ("revolute", "prismatic")


@dataclass(frozen=True)
class JointAxisEstimate:
    """One joint, world frame.

    ``joint_type`` "revolute" or "prismatic"; ``direction`` (3,) unit axis, +state opens;
    ``pivot`` (3,) metres, a point on the axis (canonically the one closest to ``grasp_point``);
    ``state`` radians (revolute) or metres (prismatic), 0 = closed; ``grasp_point`` (3,) metres, a
    point on the moving part to grasp; ``confidence`` in [0, 1].
    """

    joint_type: str
    direction: np.ndarray
    pivot: np.ndarray
    state: float
    grasp_point: np.ndarray
    confidence: float = 1.0

    def __post_init__(self) -> None:
        if self.joint_type not in JOINT_TYPES:
            raise ValueError(f"joint_type must be one of {JOINT_TYPES}, got {self.joint_type!r}")


def canonical_pivot(direction: np.ndarray, pivot: np.ndarray, grasp_point: np.ndarray) -> np.ndarray:
    """The point of the line (``pivot``, ``direction``) closest to ``grasp_point`` (all (3,), metres)."""
    u = unit(direction)
    return pivot + float((grasp_point - pivot) @ u) * u


def unit(v: np.ndarray) -> np.ndarray:
    """``v / |v|``; raises ValueError for a (near) zero vector."""
    n = float(np.linalg.norm(v))
    if n < 1e-9:
        raise ValueError("cannot normalise a zero vector")
    return np.asarray(v, dtype=np.float64) / n


def dominant_plane_inliers(points: np.ndarray, tolerance: float = 0.01, trials: int = 64,
                           seed: int = 0) -> np.ndarray:
    """Mask (M,) of the ``points`` (M, 3) within ``tolerance`` m of the plane through most of them.

    RANSAC over ``trials`` planes through three points drawn with a fixed ``seed`` (deterministic).
    """
    rng = np.random.default_rng(seed)
    best = np.zeros(len(points), dtype=bool)
    if len(points) < 3:
        return best
    for _ in range(trials):
        a, b, c = points[rng.choice(len(points), 3, replace=False)]
        n = np.cross(b - a, c - a)
        norm = np.linalg.norm(n)
        if norm < 1e-9:
            continue
        inliers = np.abs((points - a) @ (n / norm)) < tolerance
        if inliers.sum() > best.sum():
            best = inliers
    return best


def handle_point(object_points: np.ndarray, part_points: np.ndarray, min_standoff: float = 0.012,
                 max_standoff: float = 0.08, margin: float = 0.1, min_points: int = 3) -> np.ndarray | None:
    """Centre (3,) of a handle standing off a flat moving part, or None; world frame, metres.

    The part's plane is the plane through most of ``part_points`` (M, 3) (``dominant_plane_inliers``,
    refitted by PCA to those inliers: a segmentation's mislabelled body points would tilt a plain
    fit), its normal turned away from the rest of the object (a door, drawer front or lid lies on
    the outside of its body). The handle is the ``object_points`` (N, 3) (all
    of the object's points: a segmentation may miss thin handle points) between ``min_standoff``
    and ``max_standoff`` m outside that plane and within the part's in-plane extent grown by
    ``margin`` m (a view may show only some of the part), keeping those standing at least half as
    far out as the outermost ones (a bar, not the part's own surface noise); the point returned is
    their centroid moved, along their main direction, to the middle of their extent. None when
    fewer than ``min_points`` qualify or no plane holds half of the part's points (not flat).
    """
    if len(part_points) < 10 or len(object_points) < min_points:
        return None
    near = dominant_plane_inliers(part_points)
    if int(near.sum()) < max(10, len(part_points) // 2):
        return None  # no plane holds most of the part: it is not flat
    centre = part_points[near].mean(axis=0)
    vt = np.linalg.svd(part_points[near] - centre, full_matrices=False)[2]
    normal = vt[2]
    if float((object_points.mean(axis=0) - centre) @ normal) > 0.0:
        normal = -normal
    standoff = (object_points - centre) @ normal
    in_plane = (part_points - centre) @ vt[:2].T
    lo, hi = in_plane.min(axis=0) - margin, in_plane.max(axis=0) + margin
    uv = (object_points - centre) @ vt[:2].T
    keep = ((standoff > min_standoff) & (standoff < max_standoff)
            & np.all(uv >= lo, axis=1) & np.all(uv <= hi, axis=1))
    if int(keep.sum()) < min_points:
        return None
    # the handle is what stands out furthest; surface bumps and noise sit just above min_standoff
    keep &= standoff >= 0.5 * float(np.quantile(standoff[keep], 0.9))
    if int(keep.sum()) < min_points:
        return None
    handle = object_points[keep]
    centre = handle.mean(axis=0)
    # along the bar, the middle of its visible extent: the points' density varies with the view
    along = np.linalg.svd(handle - centre, full_matrices=False)[2][0]
    t = np.quantile((handle - centre) @ along, [0.05, 0.95])
    return centre + along * float(t.mean())


def grasp_point_of_part(part_points: np.ndarray, joint_type: str, direction: np.ndarray,
                        pivot: np.ndarray, quantile: float = 0.97) -> np.ndarray:
    """A grasp point on a moving part from its points (M, 3), world frame, metres.

    Revolute: the far edge, i.e. the mean of the points whose distance to the axis is at least the
    ``quantile`` of those distances (a handle sticks out, so it wins when present). Prismatic: the
    front-most points along ``direction`` (the front face and its handle), same quantile rule.
    """
    if len(part_points) == 0:
        raise ValueError("the moving part has no points")
    u = unit(direction)
    rel = part_points - pivot
    along = rel @ u
    if joint_type == "revolute":
        score = np.linalg.norm(rel - np.outer(along, u), axis=1)
    else:
        score = along
    keep = score >= np.quantile(score, quantile)
    return part_points[keep].mean(axis=0)
