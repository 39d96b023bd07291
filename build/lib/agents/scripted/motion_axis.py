"""The joint axis measured from how the part moved: a line or a circle fitted to the path of the
estimated grasp point while the hand pulled it (world frame, metres, radians).

A single view's axis a few degrees off makes the hand's commanded arc or line leave the part's own,
and the fingers slide off it. Once the part has moved far enough, the path of a point on it tells
its axis directly: a drawer's point moves along a line parallel to its axis, a door's point on a
circle about its hinge, in a plane perpendicular to it.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from agents.scripted.geometry import fit_circle, swept_angle


@dataclass(frozen=True)
class MotionAxis:
    """An axis fitted to a part's motion: unit ``direction`` (3,), signed like the estimate it
    corrects; ``pivot`` (3,) a point of a revolute axis (for a prismatic one, the path's mean);
    ``rms`` the path's distance from the fitted line or circle (metres); ``turn`` the angle from
    the estimated direction (radians)."""

    direction: np.ndarray
    pivot: np.ndarray
    rms: float
    turn: float


def fit_motion_axis(path: np.ndarray, direction: np.ndarray, pivot: np.ndarray, revolute: bool,
                    min_travel: float, min_angle: float, max_rms: float, max_turn: float,
                    max_ratio: float = 0.1, min_points: int = 3) -> MotionAxis | None:
    """The axis that the points ``path`` (M, 3) of one point of the part, in the order it moved
    through them, follow; None until they tell it reliably.

    At least ``min_points`` points (at least 3): a plane and a circle through four points fit them
    whatever they are (cabinet door with CAPT, seed 20: four grasp points, the later three of them on
    another part of the door than the first, fitted within 0.1 mm by an axis 25 deg off).
    Prismatic: the principal direction of the points, once they spread ``min_travel`` m from the
    first. Revolute: the normal of the plane they lie in and the centre of their circle in it, once
    they spread ``min_travel`` m and sweep ``min_angle`` rad about the estimated axis (unit
    ``direction`` (3,) through ``pivot`` (3,)). Refused when the points lie farther than ``max_rms``
    m (rms) from the fitted line or circle, when their spread off the line (prismatic) or off the
    plane (revolute) is more than ``max_ratio`` of their spread along it (the fitted direction would
    be uncertain by about that many radians: a short arc bends out of a line little more than noise
    moves its points), or when the fitted direction turns more than ``max_turn`` rad from the
    estimated one. The direction is signed like ``direction``.
    """
    pts = np.asarray(path, dtype=np.float64)
    u = np.asarray(direction, dtype=np.float64)
    if len(pts) < max(min_points, 3) or float(np.linalg.norm(pts - pts[0], axis=1).max()) < min_travel:
        return None
    if revolute and abs(swept_angle(u, pivot, pts[0], pts[-1])) < min_angle:
        return None
    mean = pts.mean(axis=0)
    _, sing, vt = np.linalg.svd(pts - mean, full_matrices=False)
    if revolute:  # the plane of the circle: its normal, the points' spread off it and in it
        axis, off, along = vt[2], float(sing[2]), float(sing[1])
    else:  # the line: its direction, the points' spread off it and along it
        axis, off, along = vt[0], float(np.hypot(sing[1], sing[2])), float(sing[0])
    if off > max_ratio * along:
        return None
    rms = off / np.sqrt(len(pts))
    axis = axis if float(axis @ u) >= 0.0 else -axis
    turn = float(np.arccos(np.clip(axis @ u, -1.0, 1.0)))
    if rms > max_rms or turn > max_turn:
        return None
    if not revolute:
        return MotionAxis(axis, mean, rms, turn)
    circle = fit_circle(pts, axis)
    if circle is None or circle[2] > max_rms:
        return None
    return MotionAxis(axis, circle[0], max(rms, circle[2]), turn)
