"""Rank candidate grasps by whether the Panda can reach them, then by clearance and geometric score.

A grasp found on the part's face (:mod:`capt_env.wrappers.grasp_candidates`) is only worth trying if
the arm can put its TCP there with the hand approaching along the face's normal: the pre-grasp pose
``pregrasp_distance`` out along the normal first, then the grasp itself. The arm is moved there from
its current joint angles along a straight path in small steps, each the controller's own IK step
(:func:`agents.scripted.panda_kinematics.ik_step`: CLIK from the last angles, joints stopped at
their limits): one solve of a large jump lets the unconstrained CLIK wander past the limits (a
quarter turn of the hand from the rest pose sends joint 6 to 5.5 rad, 1.7 past its limit), which
the arm, moving in steps, never does. A pose counts as reached when the TCP ends within
``pos_tolerance`` / ``rot_tolerance`` of it with every joint ``joint_margin`` inside its limits (a
joint at its limit stops the arm short, :mod:`agents.scripted.grasp_rehearsal`). Pure kinematics, no
simulator. World frame, metres, radians.
"""

from __future__ import annotations

from collections.abc import Callable, Sequence
from dataclasses import dataclass

import numpy as np

from agents.scripted.config import ScriptedOpenerConfig
from agents.scripted.geometry import axis_angle_matrix, grasp_frame, perpendicular
from agents.scripted.grasp_pose import nearer_finger_order, pitched_down
from agents.scripted.panda_kinematics import (
    PANDA_LOWER,
    PANDA_UPPER,
    base_in_world,
    ik_step,
    pose_error,
    pose_matrix,
    tcp_pose,
)
from capt_env.wrappers.estimate import unit
from capt_env.wrappers.grasp_candidates import GraspCandidate

UP = np.array([0.0, 0.0, 1.0])
APPROACH_PITCH = ScriptedOpenerConfig().approach.pitch
"""How far below level (rad) the opener points the hand at a handle (the config's default)."""
GRIPPER_OPENING = 0.08
"""The Panda's fingers open 8 cm apart: a wider handle does not fit between them."""


@dataclass(frozen=True)
class RankedGrasp:
    """A candidate grasp checked on the arm's kinematics, world frame.

    ``candidate``: the grasp; ``rotation`` (3, 3): the TCP rotation that takes it; ``reachable``:
    the arm gets to the pre-grasp and grasp poses within tolerance and joint margins; ``fits``: it is
    no wider than the open gripper and has the clearance asked for; ``q_pregrasp`` / ``q_grasp`` (7,)
    rad: where the arm ends at each (``q_grasp`` None when the pre-grasp was not reached);
    ``reason``: why it is unreachable (empty when reachable).
    """

    candidate: GraspCandidate
    rotation: np.ndarray
    reachable: bool
    fits: bool
    q_pregrasp: np.ndarray | None
    q_grasp: np.ndarray | None
    reason: str


def face_on_rotation(candidate: GraspCandidate, current: np.ndarray, pitch: float = 0.0) -> np.ndarray:
    """TCP rotation (3, 3) taking ``candidate`` square on: approach (the TCP's z) along
    ``-candidate.outward``, fingers closing (its y) across ``candidate.bar_axis`` in the face's plane,
    of the two finger orders the one nearer the current TCP rotation ``current`` (3, 3). With
    ``pitch`` (rad) an approach less than that far below level is turned down to it, about the
    horizontal axis across it, as the opener does (:func:`agents.scripted.grasp_pose.grasp_rotation`:
    the Panda's wrist cannot point level at table height); a bar along that axis stays between the
    fingers."""
    approach = -unit(candidate.outward)
    closing = perpendicular(approach, np.cross(candidate.outward, candidate.bar_axis))
    if closing is None:  # a bar along the normal: close across it in any in-plane direction
        closing = perpendicular(approach, UP)
        if closing is None:
            closing = perpendicular(approach, np.array([0.0, 1.0, 0.0]))
    assert closing is not None
    frame = grasp_frame(approach, closing)
    if pitch > 0.0:
        frame = pitched_down(frame, pitch)
    return nearer_finger_order(frame, current)


def pitched_rotation(candidate: GraspCandidate, current: np.ndarray) -> np.ndarray:
    """:func:`face_on_rotation` pitched down by the opener's ``approach.pitch`` (:data:`APPROACH_PITCH`
    rad), as the opener takes a handle: level, the hand reaches few handles in front of the robot
    from its rest pose (joint 6 ends at its limit)."""
    return face_on_rotation(candidate, current, APPROACH_PITCH)


def rank_grasps(candidates: Sequence[GraspCandidate], arm_qpos: np.ndarray, tcp_in_world: np.ndarray,
                rotation_for: Callable[[GraspCandidate, np.ndarray], np.ndarray] = pitched_rotation,
                pregrasp_distance: float = 0.1, step_m: float = 0.05, step_rad: float = 0.2,
                pos_tolerance: float = 0.005, rot_tolerance: float = 0.05, joint_margin: float = 0.05,
                max_width: float = GRIPPER_OPENING, min_clearance: float = 0.03) -> list[RankedGrasp]:
    """``candidates`` checked on the Panda's kinematics and ranked: reachable ones first, then those
    that ``fits`` (``width`` <= ``max_width`` m and ``clearance`` >= ``min_clearance`` m), then by
    geometric score and clearance; the input order breaks ties.

    ``arm_qpos`` (7+,) rad: the arm's joint angles now (fingers ignored); ``tcp_in_world`` (4, 4): the
    TCP pose they give, from which the base's pose is recovered. ``rotation_for(candidate, current
    TCP rotation (3, 3))`` gives the grasp's TCP rotation (3, 3), world frame (default
    :func:`pitched_rotation`, as the opener takes a handle; :func:`face_on_rotation` is level). The
    pre-grasp pose is ``pregrasp_distance`` m out along the candidate's ``outward``, same rotation.
    The arm is moved there from where it is, then in to the grasp, in controller steps of at most
    ``step_m`` m and ``step_rad`` rad (:func:`_reach`). Reached: the TCP ends within ``pos_tolerance`` m and
    ``rot_tolerance`` rad of the pose with every joint at least ``joint_margin`` rad inside its
    limits.
    """
    q = np.asarray(arm_qpos, dtype=np.float64).reshape(-1)[:7]
    tcp = np.asarray(tcp_in_world, dtype=np.float64)
    world_to_base = np.linalg.inv(base_in_world(q, tcp))
    checked = []
    for g in candidates:
        rotation = rotation_for(g, tcp[:3, :3])
        pre = world_to_base @ pose_matrix(g.point + pregrasp_distance * unit(g.outward), rotation)
        grasp = world_to_base @ pose_matrix(np.asarray(g.point, dtype=np.float64), rotation)
        q_pre, why = _reach(q, tcp_pose(q), pre, step_m, step_rad, pos_tolerance, rot_tolerance,
                            joint_margin)
        q_grasp, reason = None, f"pre-grasp: {why}" if why else ""
        if not why:  # the arm moves in from the pre-grasp pose
            q_grasp, why = _reach(q_pre, tcp_pose(q_pre), grasp, step_m, step_rad, pos_tolerance,
                                  rot_tolerance, joint_margin)
            reason = f"grasp: {why}" if why else ""
        fits = g.width <= max_width and g.clearance >= min_clearance
        checked.append(RankedGrasp(g, rotation, not reason, fits, q_pre, q_grasp, reason))
    order = sorted(range(len(checked)), key=lambda i: (not checked[i].reachable, not checked[i].fits,
                                                       -checked[i].candidate.score,
                                                       -checked[i].candidate.clearance, i))
    return [checked[i] for i in order]


def _reach(q: np.ndarray, start: np.ndarray, target: np.ndarray, step_m: float, step_rad: float,
           pos_tolerance: float, rot_tolerance: float, joint_margin: float) -> tuple[np.ndarray, str]:
    """(joint angles (7,) rad where the arm ends, why it does not reach ``target`` (4, 4, base frame):
    empty when it does), moving from angles ``q`` (7,) and TCP pose ``start`` (4, 4, base frame)
    along the straight path (position line, rotation about one axis) in steps of at most ``step_m``
    m and ``step_rad`` rad, each a controller step (:func:`ik_step`: the IK from the last angles,
    joints stopped at their limits, held where it does not converge)."""
    err = pose_error(target, start)
    n = max(1, int(np.ceil(max(np.linalg.norm(err[:3]) / step_m, np.linalg.norm(err[3:]) / step_rad))))
    for k in range(1, n + 1):
        share = k / n
        waypoint = pose_matrix(start[:3, 3] + share * err[:3],
                               axis_angle_matrix(err[3:], share) @ start[:3, :3])
        q = ik_step(q, waypoint)
    err = pose_error(target, tcp_pose(q))
    if np.linalg.norm(err[:3]) > pos_tolerance or np.linalg.norm(err[3:]) > rot_tolerance:
        return q, f"stopped {np.linalg.norm(err[:3]):.3f} m, {np.linalg.norm(err[3:]):.2f} rad short"
    outside = np.flatnonzero((q < PANDA_LOWER + joint_margin) | (q > PANDA_UPPER - joint_margin))
    if len(outside):
        return q, f"joint {int(outside[0]) + 1} within {joint_margin} rad of its limit"
    return q, ""
