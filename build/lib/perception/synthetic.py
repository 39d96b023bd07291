"""Synthetic two-part box objects with one revolute (laptop-like lid) or prismatic (drawer) joint, used to
exercise CAPT (paper Sec. III) in docs and tests without a simulator. Points are sampled on the box
surfaces (area-weighted), metres, radians; labels: 0 = base, 1 = moving part.
"""

from __future__ import annotations

import numpy as np

from perception.data import Sample


def _box_surface(rng: np.random.Generator, size: np.ndarray, centre: np.ndarray, n: int) -> np.ndarray:
    sx, sy, sz = size
    areas = np.array([sy * sz, sy * sz, sx * sz, sx * sz, sx * sy, sx * sy])
    face = rng.choice(6, size=n, p=areas / areas.sum())
    uv = rng.uniform(-0.5, 0.5, size=(n, 3)) * size
    axis = face // 2
    sign = np.where(face % 2 == 0, -0.5, 0.5)
    uv[np.arange(n), axis] = sign * size[axis]
    return uv + centre


def _rot(u: np.ndarray, angle: float) -> np.ndarray:
    k = np.array([[0, -u[2], u[1]], [u[2], 0, -u[0]], [-u[1], u[0], 0]])
    return np.eye(3) + np.sin(angle) * k + (1 - np.cos(angle)) * k @ k


def make_box_sample(rng: np.random.Generator, num_points: int = 512, joint_type: str = "revolute",
                    state: float | None = None, instance_id: int = 0) -> Sample:
    """A random two-part box object. Revolute: a lid hinged on the base's back top edge, axis -x
    (+state opens upward), state in [0, 2] rad. Prismatic: a drawer sliding out along -y, state in
    [0, 0.8 x drawer depth] m. Object roughly 0.2-0.4 m wide, centred near the origin."""
    w, d = rng.uniform(0.2, 0.4), rng.uniform(0.15, 0.3)
    n_base = num_points // 2
    if joint_type == "revolute":
        h_base, h_lid = rng.uniform(0.02, 0.05), rng.uniform(0.01, 0.03)
        limits = np.array([0.0, 2.0])
        state = float(rng.uniform(*limits)) if state is None else float(state)
        base = _box_surface(rng, np.array([w, d, h_base]), np.zeros(3), n_base)
        lid = _box_surface(rng, np.array([w, d, h_lid]), np.array([0, 0, h_base / 2 + h_lid / 2]),
                           num_points - n_base)
        u = np.array([-1.0, 0.0, 0.0])
        q = np.array([0.0, d / 2, h_base / 2])
        lid = (lid - q) @ _rot(u, state).T + q
        code = 0
    elif joint_type == "prismatic":
        h = rng.uniform(0.1, 0.25)
        limits = np.array([0.0, 0.8 * d])
        state = float(rng.uniform(*limits)) if state is None else float(state)
        base = _box_surface(rng, np.array([w, d, h]), np.zeros(3), n_base)
        drawer = _box_surface(rng, np.array([0.9 * w, 0.95 * d, 0.6 * h]), np.zeros(3), num_points - n_base)
        u = np.array([0.0, -1.0, 0.0])
        lid = drawer + state * u
        q = np.zeros(3)
        code = 1
    else:
        raise ValueError(f"joint_type must be revolute or prismatic, got {joint_type!r}")
    points = np.concatenate([base, lid])
    labels = np.concatenate([np.zeros(len(base), np.int64), np.ones(len(lid), np.int64)])
    centroid = points.mean(axis=0)
    q = q + ((centroid - q) @ u) * u
    return Sample(points=points.astype(np.float32), part_labels=labels, joint_types=np.array([code]),
                  joint_dirs=u[None].astype(np.float32), joint_pivots=q[None].astype(np.float32),
                  joint_states=np.array([state], np.float32), joint_limits=limits[None].astype(np.float32),
                  joint_child_part=np.array([1]), joint_mask=np.array([True]),
                  category=f"box_{joint_type}", instance_id=instance_id)
