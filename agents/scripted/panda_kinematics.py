"""The Franka Panda's kinematics and its ``pd_ee_delta_pose`` controller's IK, from ManiSkill's URDF.

Everything comes from the URDF the simulated robot is loaded from (``Panda.urdf_path``): the joint
chain from the base (``panda_link0``) to the TCP link ``panda_hand_tcp`` and the arm joints' limits,
which the simulator's joints stop at. Forward kinematics and the Jacobian compose the chain's joint
origins and axes in double precision. :func:`solve_ik` is the controller's own IK: SAPIEN's
pinocchio model of the same URDF, as ManiSkill's controllers build it on the CPU
(:class:`mani_skill.agents.controllers.utils.kinematics.Kinematics`), solved by closed-loop IK (CLIK,
100 iterations from the current joint angles, the limits unknown to the solver). :func:`ik_step` is
one control step: a solve that does not converge leaves the joint targets where the joints are (the
controller then holds the arm still), and each joint stops at its limit, as the simulated drives do;
the other joints keep the solution's angles and do not make up for it. Poses are 4x4 homogeneous
matrices in the robot's base frame (metres); joint angles in radians. The base's pose in the world is
not needed: :func:`base_in_world` recovers it from one observed TCP pose and the joint angles that
gave it.
"""

from __future__ import annotations

from dataclasses import dataclass
from functools import lru_cache

import numpy as np
import sapien
from lxml import etree
from mani_skill.agents.robots.panda.panda import Panda
from sapien.wrapper.pinocchio_model import PinocchioModel

from agents.scripted.geometry import rotation_error

ARM_JOINTS = tuple(f"panda_joint{i}" for i in range(1, 8))
FINGER_JOINTS = ("panda_finger_joint1", "panda_finger_joint2")
BASE_LINK, TCP_LINK = "panda_link0", "panda_hand_tcp"
IK_MAX_ITERATIONS = 100  # the controller's CLIK budget (Kinematics.compute_ik on the CPU)


@dataclass(frozen=True)
class _Joint:
    """One joint of the chain: its origin (4, 4) in the parent link and, for an arm joint, its
    index in the arm's angles and its unit axis (3,) in its child link; fixed joints have none."""

    origin: np.ndarray
    index: int | None
    axis: np.ndarray | None


def _origin(joint: etree._Element) -> np.ndarray:
    """(4, 4) of a URDF joint's ``<origin xyz rpy>`` (rpy: fixed-axis roll, pitch, yaw)."""
    node = joint.find("origin")
    attrs = {} if node is None else node.attrib
    xyz = [float(v) for v in attrs.get("xyz", "0 0 0").split()]
    roll, pitch, yaw = (float(v) for v in attrs.get("rpy", "0 0 0").split())
    cr, sr, cp, sp = np.cos(roll), np.sin(roll), np.cos(pitch), np.sin(pitch)
    cy, sy = np.cos(yaw), np.sin(yaw)
    t = np.eye(4)
    t[:3, :3] = np.array([[cy, -sy, 0.0], [sy, cy, 0.0], [0.0, 0.0, 1.0]]) @ \
        np.array([[cp, 0.0, sp], [0.0, 1.0, 0.0], [-sp, 0.0, cp]]) @ \
        np.array([[1.0, 0.0, 0.0], [0.0, cr, -sr], [0.0, sr, cr]])
    t[:3, 3] = xyz
    return t


@lru_cache(maxsize=1)
def _urdf() -> str:
    with open(Panda.urdf_path) as f:
        return f.read()


def _parse(urdf: str) -> tuple[list[_Joint], np.ndarray, np.ndarray]:
    """The joint chain from the base to the TCP link and the arm joints' (lower, upper) limits (7,)
    rad, from the URDF text ``urdf``."""
    joints = [j for j in etree.fromstring(urdf.encode("utf-8")) if j.tag == "joint"]
    by_child = {j.find("child").get("link"): j for j in joints}
    chain, link = [], TCP_LINK
    while link != BASE_LINK:
        joint = by_child[link]
        name = joint.get("name")
        if joint.get("type") == "fixed":
            chain.append(_Joint(_origin(joint), None, None))
        elif name in ARM_JOINTS and joint.get("type") == "revolute":
            axis = np.array([float(v) for v in joint.find("axis").get("xyz").split()])
            chain.append(_Joint(_origin(joint), ARM_JOINTS.index(name), axis / np.linalg.norm(axis)))
        else:
            raise ValueError(f"unexpected joint {name} ({joint.get('type')}) between the base and the TCP")
        link = joint.find("parent").get("link")
    named = {j.get("name"): j for j in joints}
    limits = np.array([[float(named[n].find("limit").get(k)) for k in ("lower", "upper")]
                       for n in ARM_JOINTS])
    return chain[::-1], limits[:, 0], limits[:, 1]


_CHAIN, PANDA_LOWER, PANDA_UPPER = _parse(_urdf())
_ARM_CHAIN = [j for j in _CHAIN if j.index is not None]  # joints 1..7 in order


@lru_cache(maxsize=1)
def _model() -> tuple[PinocchioModel, int]:
    """The controller's pinocchio model of the Panda (arm then finger joints, as the simulated
    articulation orders them) and the TCP link's index in it."""
    model = PinocchioModel(_urdf(), [0.0, 0.0, -9.81])
    model.set_joint_order([*ARM_JOINTS, *FINGER_JOINTS])
    model.set_link_order([TCP_LINK])
    return model, 0


_ARM_MASK = np.array([1] * len(ARM_JOINTS) + [0] * len(FINGER_JOINTS), dtype=np.int32)


def pose_matrix(position: np.ndarray, rotation: np.ndarray) -> np.ndarray:
    """Homogeneous pose (4, 4) from a position (3,) m and a rotation (3, 3)."""
    pose = np.eye(4)
    pose[:3, :3] = rotation
    pose[:3, 3] = position
    return pose


def _arm(q: np.ndarray) -> np.ndarray:
    q = np.asarray(q, dtype=np.float64).reshape(-1)
    if q.shape != (7,):
        raise ValueError(f"the Panda has 7 arm joints, got {q.shape[0]} angles")
    return q


def _axis_rotation(axis: np.ndarray, angle: float) -> np.ndarray:
    """(4, 4) rotation by ``angle`` rad about unit ``axis`` (3,) (Rodrigues)."""
    k = np.array([[0.0, -axis[2], axis[1]], [axis[2], 0.0, -axis[0]], [-axis[1], axis[0], 0.0]])
    t = np.eye(4)
    t[:3, :3] = np.eye(3) + np.sin(angle) * k + (1.0 - np.cos(angle)) * (k @ k)
    return t


def joint_frames(q: np.ndarray) -> tuple[list[np.ndarray], np.ndarray]:
    """Frames (4, 4) of joints 1..7 (each at its joint, its axis along z) and the TCP pose (4, 4),
    base frame, for the seven joint angles ``q`` (rad)."""
    q = _arm(q)
    t = np.eye(4)
    frames = []
    for joint in _CHAIN:
        t = t @ joint.origin
        if joint.index is not None:
            frames.append(t)
            t = t @ _axis_rotation(joint.axis, q[joint.index])
    return frames, t


def tcp_pose(q: np.ndarray) -> np.ndarray:
    """TCP pose (4, 4) in the base frame for joint angles ``q`` (7,) rad."""
    return joint_frames(q)[1]


def jacobian(q: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Geometric Jacobian (6, 7) of the TCP (rows: linear m/rad of the TCP point, then angular), base
    frame, and the TCP pose (4, 4)."""
    frames, tcp = joint_frames(q)
    jac = np.empty((6, 7))
    for joint, f in zip(_ARM_CHAIN, frames, strict=True):
        z = f[:3, :3] @ joint.axis
        jac[:3, joint.index] = np.cross(z, tcp[:3, 3] - f[:3, 3])
        jac[3:, joint.index] = z
    return jac, tcp


def base_in_world(q: np.ndarray, tcp_in_world: np.ndarray) -> np.ndarray:
    """The base's pose (4, 4) in the world, from joint angles ``q`` (7,) and the TCP pose (4, 4) in the
    world that they gave."""
    return tcp_in_world @ np.linalg.inv(tcp_pose(q))


def pose_error(target: np.ndarray, current: np.ndarray) -> np.ndarray:
    """(6,) position error (m) and rotation vector (rad) taking ``current`` (4, 4) to ``target`` (4, 4),
    both in the same frame."""
    return np.concatenate([target[:3, 3] - current[:3, 3], rotation_error(target[:3, :3], current[:3, :3])])


def solve_ik(q: np.ndarray, target: np.ndarray,
             max_iterations: int = IK_MAX_ITERATIONS) -> np.ndarray | None:
    """The controller's IK: joint angles (7,) rad that put the TCP at ``target`` (4, 4, base frame),
    found by CLIK from ``q`` (7,) without joint limits; None when it does not converge."""
    model, tcp_link = _model()
    fingers = np.zeros(len(FINGER_JOINTS))  # (they do not move the TCP)
    result, success, _ = model.compute_inverse_kinematics(
        tcp_link, sapien.Pose(np.asarray(target, dtype=np.float64)),
        initial_qpos=np.concatenate([_arm(q), fingers]), active_qmask=_ARM_MASK,
        max_iterations=max_iterations)
    return np.asarray(result, dtype=np.float64)[:7] if success else None


def ik_step(q: np.ndarray, target: np.ndarray, max_iterations: int = IK_MAX_ITERATIONS) -> np.ndarray:
    """Joint angles (7,) rad after one ``pd_ee_delta_pose`` control step from ``q`` towards TCP pose
    ``target`` (4, 4, base frame): the controller's IK solution, each joint stopped at its limit (a
    joint at its limit stays there, as on the robot); ``q`` itself when the IK does not converge."""
    q = _arm(q)
    solved = solve_ik(q, target, max_iterations)
    return q.copy() if solved is None else np.clip(solved, PANDA_LOWER, PANDA_UPPER)
