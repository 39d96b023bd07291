"""Small rigid-body geometry helpers: box corners, (w, x, y, z) quaternions, joint-axis construction.

All functions are pure numpy. Quaternions are (w, x, y, z) unit quaternions; points and directions
are (3,) or (N, 3) arrays in metres in whatever frame the caller works in.
"""

from __future__ import annotations

from collections.abc import Sequence

import numpy as np

from capt_env.objects.spec import Box, Cylinder, Shape

_CORNER_SIGNS = np.array([[sx, sy, sz] for sx in (-1.0, 1.0) for sy in (-1.0, 1.0) for sz in (-1.0, 1.0)])


def quat_to_matrix(quat: Sequence[float]) -> np.ndarray:
    """(3, 3) rotation matrix of a (w, x, y, z) quaternion (normalised first)."""
    w, x, y, z = np.asarray(quat, dtype=np.float64) / np.linalg.norm(quat)
    return np.array(
        [
            [1 - 2 * (y * y + z * z), 2 * (x * y - w * z), 2 * (x * z + w * y)],
            [2 * (x * y + w * z), 1 - 2 * (x * x + z * z), 2 * (y * z - w * x)],
            [2 * (x * z - w * y), 2 * (y * z + w * x), 1 - 2 * (x * x + y * y)],
        ]
    )


def quat_multiply(a: Sequence[float], b: Sequence[float]) -> np.ndarray:
    """Hamilton product a * b of (w, x, y, z) quaternions (apply b first, then a)."""
    aw, ax, ay, az = a
    bw, bx, by, bz = b
    return np.array(
        [
            aw * bw - ax * bx - ay * by - az * bz,
            aw * bx + ax * bw + ay * bz - az * by,
            aw * by - ax * bz + ay * bw + az * bx,
            aw * bz + ax * by - ay * bx + az * bw,
        ]
    )


def quat_from_axis_angle(axis: Sequence[float], angle: float) -> np.ndarray:
    """(w, x, y, z) rotation by ``angle`` radians about the unit-normalised ``axis``."""
    axis = np.asarray(axis, dtype=np.float64)
    axis = axis / np.linalg.norm(axis)
    half = 0.5 * angle
    return np.concatenate([[np.cos(half)], np.sin(half) * axis])


def quat_from_x_to(direction: Sequence[float]) -> np.ndarray:
    """(w, x, y, z) quaternion of the shortest rotation taking +x onto ``direction`` (any length > 0).

    This is how a joint frame is built: the simulator's joint axis is the frame's x-axis.
    """
    d = np.asarray(direction, dtype=np.float64)
    norm = np.linalg.norm(d)
    if norm < 1e-12:
        raise ValueError("direction must be non-zero")
    d = d / norm
    x = np.array([1.0, 0.0, 0.0])
    dot = float(np.clip(x @ d, -1.0, 1.0))
    if dot < -1.0 + 1e-9:  # opposite: turn half a revolution about z
        return np.array([0.0, 0.0, 0.0, 1.0])
    q = np.concatenate([[1.0 + dot], np.cross(x, d)])
    return q / np.linalg.norm(q)


def box_corners(box: Box) -> np.ndarray:
    """(8, 3) corners of ``box`` in its link's frame, metres."""
    local = _CORNER_SIGNS * np.asarray(box.half_size, dtype=np.float64)
    return local @ quat_to_matrix(box.quat).T + np.asarray(box.pos, dtype=np.float64)


def shape_points(shape: Shape, count: int = 16) -> np.ndarray:
    """Points (M, 3) whose convex hull is ``shape`` (a mesh's vertices; for a cylinder, ``count``
    points on each end circle, a hull slightly inside the true one), link frame, metres."""
    if isinstance(shape, Cylinder):
        t = np.linspace(0.0, 2 * np.pi, count, endpoint=False)
        ring = np.stack([np.zeros(count), shape.radius * np.cos(t), shape.radius * np.sin(t)], axis=-1)
        local = np.concatenate([ring + [shape.half_length, 0, 0], ring - [shape.half_length, 0, 0]])
        return local @ quat_to_matrix(shape.quat).T + np.asarray(shape.pos, dtype=np.float64)
    return np.asarray(shape.vertices, dtype=np.float64).reshape(-1, 3)


def rotate_about_axis(
    points: np.ndarray, axis: Sequence[float], pivot: Sequence[float], angle: float
) -> np.ndarray:
    """Rotate (N, 3) ``points`` by ``angle`` radians about the line through ``pivot`` along ``axis``."""
    rot = quat_to_matrix(quat_from_axis_angle(axis, angle))
    pivot = np.asarray(pivot, dtype=np.float64)
    return (np.asarray(points, dtype=np.float64) - pivot) @ rot.T + pivot


def opening_axis(lever: Sequence[float], direction: Sequence[float]) -> tuple[float, float, float]:
    """Unit revolute axis under which a point at ``lever`` (from the pivot) starts moving along
    ``direction`` for increasing joint state (right-hand rule): normalize(lever x direction)."""
    axis = np.cross(np.asarray(lever, dtype=np.float64), np.asarray(direction, dtype=np.float64))
    norm = np.linalg.norm(axis)
    if norm < 1e-12:
        raise ValueError("lever and direction must not be parallel")
    return tuple(float(v) + 0.0 for v in axis / norm)  # + 0.0 turns -0.0 into 0.0
