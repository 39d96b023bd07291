"""Forward kinematics and damped least-squares IK of the Franka Panda arm, in numpy.

Franka's published (Craig, modified) Denavit-Hartenberg parameters, the flange-to-hand turn of
-pi/4 about z and ManiSkill's TCP 0.1034 m past the hand. Poses are 4x4 homogeneous matrices in the
robot's base frame (metres); joint angles in radians. The base's pose in the world is not needed:
:func:`base_in_world` recovers it from one observed TCP pose and the joint angles that gave it.
"""

from __future__ import annotations

import numpy as np

from agents.scripted.geometry import rotation_error

# (a m, d m, alpha rad) of joints 1..7 (theta = q_i), then the flange (theta = 0)
_DH = np.array([
    [0.0, 0.333, 0.0],
    [0.0, 0.0, -np.pi / 2],
    [0.0, 0.316, np.pi / 2],
    [0.0825, 0.0, np.pi / 2],
    [-0.0825, 0.384, -np.pi / 2],
    [0.0, 0.0, np.pi / 2],
    [0.088, 0.0, np.pi / 2],
    [0.0, 0.107, 0.0],
])
_HAND_YAW = -np.pi / 4  # the hand is turned on the flange about z
_TCP_OFFSET = 0.1034  # m, from the hand's origin along its z (between the fingertips)

PANDA_LOWER = np.array([-2.8973, -1.7628, -2.8973, -3.0718, -2.8973, -0.0175, -2.8973])
PANDA_UPPER = np.array([2.8973, 1.7628, 2.8973, -0.0698, 2.8973, 3.7525, 2.8973])


def pose_matrix(position: np.ndarray, rotation: np.ndarray) -> np.ndarray:
    """Homogeneous pose (4, 4) from a position (3,) m and a rotation (3, 3)."""
    pose = np.eye(4)
    pose[:3, :3] = rotation
    pose[:3, 3] = position
    return pose


def _dh(a: float, d: float, alpha: float, theta: float) -> np.ndarray:
    """Modified DH transform: rotate alpha about x, shift a along x, rotate theta about z, shift d."""
    ca, sa, ct, st = np.cos(alpha), np.sin(alpha), np.cos(theta), np.sin(theta)
    return np.array([
        [ct, -st, 0.0, a],
        [st * ca, ct * ca, -sa, -d * sa],
        [st * sa, ct * sa, ca, d * ca],
        [0.0, 0.0, 0.0, 1.0],
    ])


def _tcp_in_flange() -> np.ndarray:
    c, s = np.cos(_HAND_YAW), np.sin(_HAND_YAW)
    t = np.eye(4)
    t[:3, :3] = [[c, -s, 0.0], [s, c, 0.0], [0.0, 0.0, 1.0]]
    t[2, 3] = _TCP_OFFSET
    return t


_TCP_IN_FLANGE = _tcp_in_flange()


def joint_frames(q: np.ndarray) -> tuple[list[np.ndarray], np.ndarray]:
    """Frames (4, 4) of joints 1..7 (each one's z is its axis) and the TCP pose (4, 4), base frame,
    for the seven joint angles ``q`` (rad)."""
    q = np.asarray(q, dtype=np.float64).reshape(-1)
    if q.shape != (7,):
        raise ValueError(f"the Panda has 7 arm joints, got {q.shape[0]} angles")
    t = np.eye(4)
    frames = []
    for i in range(7):
        t = t @ _dh(*_DH[i], q[i])
        frames.append(t)
    tcp = t @ _dh(*_DH[7], 0.0) @ _TCP_IN_FLANGE
    return frames, tcp


def tcp_pose(q: np.ndarray) -> np.ndarray:
    """TCP pose (4, 4) in the base frame for joint angles ``q`` (7,) rad."""
    return joint_frames(q)[1]


def jacobian(q: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Geometric Jacobian (6, 7) of the TCP (rows: linear m/rad, then angular), base frame, and the
    TCP pose (4, 4)."""
    frames, tcp = joint_frames(q)
    jac = np.empty((6, 7))
    for i, f in enumerate(frames):
        z = f[:3, 2]
        jac[:3, i] = np.cross(z, tcp[:3, 3] - f[:3, 3])
        jac[3:, i] = z
    return jac, tcp


def base_in_world(q: np.ndarray, tcp_in_world: np.ndarray) -> np.ndarray:
    """The base's pose (4, 4) in the world, from joint angles ``q`` (7,) and the TCP pose (4, 4) in the
    world that they gave."""
    return tcp_in_world @ np.linalg.inv(tcp_pose(q))


def pose_error(target: np.ndarray, current: np.ndarray) -> np.ndarray:
    """(6,) position error (m) and rotation vector (rad) taking ``current`` (4, 4) to ``target`` (4, 4),
    both in the same frame."""
    return np.concatenate([target[:3, 3] - current[:3, 3], rotation_error(target[:3, :3], current[:3, :3])])


def ik_step(q: np.ndarray, target: np.ndarray, iterations: int = 3, damping: float = 0.05) -> np.ndarray:
    """Joint angles (7,) rad moved from ``q`` towards TCP pose ``target`` (4, 4, base frame) by
    ``iterations`` damped least-squares steps, each clamped to the joint limits (a joint at its limit
    stays there, as on the robot)."""
    q = np.asarray(q, dtype=np.float64).copy()
    for _ in range(iterations):
        jac, tcp = jacobian(q)
        err = pose_error(target, tcp)
        dq = jac.T @ np.linalg.solve(jac @ jac.T + damping ** 2 * np.eye(6), err)
        q = np.clip(q + dq, PANDA_LOWER, PANDA_UPPER)
    return q
