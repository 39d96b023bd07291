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


def handle_point(object_points: np.ndarray, part_points: np.ndarray, min_standoff: float = 0.012,
                 max_standoff: float = 0.08, margin: float = 0.1, min_points: int = 3) -> np.ndarray | None:
    """Centre (3,) of a handle standing off a flat moving part, or None; world frame, metres.

    The part's plane is fitted to ``part_points`` (M, 3) by PCA, its offset the median (robust to a
    few mislabelled points), and its normal turned away from the rest of the object (a door, drawer
    front or lid lies on the outside of its body). The handle is the ``object_points`` (N, 3) (all
    of the object's points: a segmentation may miss thin handle points) between ``min_standoff``
    and ``max_standoff`` m outside that plane and within the part's in-plane extent grown by
    ``margin`` m (a view may show only some of the part). None when fewer than ``min_points``
    qualify or the part is not flat.
    """
    if len(part_points) < 10 or len(object_points) < min_points:
        return None
    centre = part_points.mean(axis=0)
    _, sv, vt = np.linalg.svd(part_points - centre, full_matrices=False)
    if sv[2] > 0.5 * sv[1]:
        return None
    normal = vt[2]
    plane = float(np.median((part_points - centre) @ normal))
    if float((object_points.mean(axis=0) - centre) @ normal) > plane:
        normal, plane = -normal, -plane
    standoff = (object_points - centre) @ normal - plane
    in_plane = (part_points - centre) @ vt[:2].T
    lo, hi = in_plane.min(axis=0) - margin, in_plane.max(axis=0) + margin
    uv = (object_points - centre) @ vt[:2].T
    keep = ((standoff > min_standoff) & (standoff < max_standoff)
            & np.all(uv >= lo, axis=1) & np.all(uv <= hi, axis=1))
    return object_points[keep].mean(axis=0) if int(keep.sum()) >= min_points else None


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
