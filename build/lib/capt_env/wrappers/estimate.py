"""The joint-axis estimate of the target joint, world frame, as the observation and the agents see it.

Also the two canonical choices an estimate needs: the pivot (the point of the axis closest to the
grasp point) and the fallback grasp point of a moving part (the far edge from a revolute axis or the
front-most points along a prismatic axis); the handle and the opening sign come from the part's
geometry in ``moving_part_geometry``.
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


def away_from_joint(est: JointAxisEstimate) -> np.ndarray:
    """Unit world direction (3,) away from the joint at ``est``'s grasp point: along the radius from
    the axis (revolute; zeros when the grasp point lies on the axis) or along the axis (prismatic)."""
    u = unit(est.direction)
    if est.joint_type == "prismatic":
        return u
    radial = est.grasp_point - est.pivot
    radial = radial - float(radial @ u) * u
    norm = float(np.linalg.norm(radial))
    return radial / norm if norm > 1e-9 else np.zeros(3)


def unit(v: np.ndarray) -> np.ndarray:
    """``v / |v|``; raises ValueError for a (near) zero vector."""
    n = float(np.linalg.norm(v))
    if n < 1e-9:
        raise ValueError("cannot normalise a zero vector")
    return np.asarray(v, dtype=np.float64) / n


def grasp_point_of_part(part_points: np.ndarray, joint_type: str, direction: np.ndarray,
                        pivot: np.ndarray, quantile: float = 0.97, band: float = 0.01) -> np.ndarray:
    """A grasp point on a moving part from its points (M, 3), world frame, metres.

    Revolute: the far edge, i.e. the mean of the points whose distance to the axis is at least the
    ``quantile`` of those distances and within ``band`` metres of the farthest (their 99.5th
    percentile), so a lip or handle sticking out past the edge wins over the edge's full length.
    Prismatic: the front-most points along ``direction`` (the front face and its handle), same rule.
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
    floor = max(float(np.quantile(score, quantile)), float(np.quantile(score, 0.995)) - band)
    keep = score >= floor
    return part_points[keep].mean(axis=0)
