"""Rotation helpers of the scripted opener (world frame; quaternions wxyz like ManiSkill)."""

from __future__ import annotations

import numpy as np
from scipy.spatial.transform import Rotation


def quat_to_matrix(q_wxyz: np.ndarray) -> np.ndarray:
    """(4,) wxyz quaternion -> (3, 3) rotation matrix."""
    return Rotation.from_quat(np.asarray(q_wxyz, dtype=np.float64), scalar_first=True).as_matrix()


def axis_angle_matrix(axis: np.ndarray, angle: float) -> np.ndarray:
    """(3, 3) rotation by ``angle`` radians about unit ``axis`` (3,)."""
    return Rotation.from_rotvec(np.asarray(axis, dtype=np.float64) * angle).as_matrix()


def rotation_error(r_des: np.ndarray, r_cur: np.ndarray) -> np.ndarray:
    """World-frame rotation vector (3,) radians taking ``r_cur`` to ``r_des`` (R_des = R(e) R_cur)."""
    return Rotation.from_matrix(r_des @ r_cur.T).as_rotvec()


def perpendicular(v: np.ndarray, hint: np.ndarray) -> np.ndarray | None:
    """Unit component of ``hint`` perpendicular to unit ``v``; None when they are (near) parallel."""
    w = hint - float(hint @ v) * v
    n = float(np.linalg.norm(w))
    return None if n < 1e-3 else w / n


def grasp_frame(approach: np.ndarray, closing: np.ndarray) -> np.ndarray:
    """Panda TCP rotation (columns x, y = finger closing, z = approach), as ManiSkill's build_grasp_pose."""
    return np.stack([np.cross(closing, approach), closing, approach], axis=1)


def clip_norm(v: np.ndarray, max_norm: float) -> np.ndarray:
    """``v`` scaled down to norm ``max_norm`` if longer."""
    n = float(np.linalg.norm(v))
    return v if n <= max_norm else v * (max_norm / n)


def off_axis(v: np.ndarray, axis: np.ndarray) -> np.ndarray:
    """The part (3,) of vector ``v`` (3,) perpendicular to unit ``axis`` (3,)."""
    v = np.asarray(v, dtype=np.float64)
    return v - float(v @ axis) * axis


def out_of_sweep(p: np.ndarray, axis: np.ndarray, pivot: np.ndarray, reach: np.ndarray,
                 clearance: float) -> np.ndarray | None:
    """The point straight out from the line along unit ``axis`` (3,) through ``pivot`` (3,), from ``p``
    (3,), ``clearance`` (m) beyond the radius of ``reach`` (3,) about that line (the sweep of a part
    turning about it); ``p`` itself when already that far out, None when ``p`` is on the line."""
    radial = off_axis(np.asarray(p, dtype=np.float64) - pivot, axis)
    radius = float(np.linalg.norm(radial))
    if radius < 1e-6:
        return None
    clear = float(np.linalg.norm(off_axis(np.asarray(reach, dtype=np.float64) - pivot, axis))) + clearance
    return p + max(clear - radius, 0.0) * radial / radius


def swept_angle(axis: np.ndarray, pivot: np.ndarray, start: np.ndarray, now: np.ndarray) -> float:
    """Signed angle (radians, right-handed about unit ``axis``) that carries point ``start`` (3,) to
    point ``now`` (3,) about the line through ``pivot`` (3,); components along the axis are ignored.
    0 when either point lies on the line."""
    a = off_axis(np.asarray(start, dtype=np.float64) - pivot, axis)
    b = off_axis(np.asarray(now, dtype=np.float64) - pivot, axis)
    if np.linalg.norm(a) < 1e-6 or np.linalg.norm(b) < 1e-6:
        return 0.0
    return float(np.arctan2(float(np.cross(a, b) @ axis), float(a @ b)))


def fit_circle(points: np.ndarray, axis: np.ndarray) -> tuple[np.ndarray, float, float] | None:
    """Least-squares circle through ``points`` (M, 3) seen along unit ``axis`` (3,): (centre (3,),
    radius, rms distance of the points from the circle), metres, world frame. The centre lies in the
    plane through the points' mean perpendicular to ``axis``; components along ``axis`` are ignored.
    None for fewer than 3 points or collinear ones."""
    pts = np.asarray(points, dtype=np.float64)
    if len(pts) < 3:
        return None
    e1 = perpendicular(axis, np.array([1.0, 0.0, 0.0]))
    if e1 is None:
        e1 = perpendicular(axis, np.array([0.0, 1.0, 0.0]))
    assert e1 is not None
    e2 = np.cross(axis, e1)
    mean = pts.mean(axis=0)
    xy = np.stack([(pts - mean) @ e1, (pts - mean) @ e2], axis=1)
    # x^2 + y^2 = 2 a x + 2 b y + c: linear in (a, b, c); the centre is (a, b)
    design = np.column_stack([2.0 * xy, np.ones(len(xy))])
    (a, b, c), _, rank, _ = np.linalg.lstsq(design, (xy ** 2).sum(axis=1), rcond=None)
    if rank < 3:
        return None
    radius = float(np.sqrt(max(c + a * a + b * b, 0.0)))
    rms = float(np.sqrt(np.mean((np.linalg.norm(xy - [a, b], axis=1) - radius) ** 2)))
    return mean + a * e1 + b * e2, radius, rms
