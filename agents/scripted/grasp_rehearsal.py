"""Rehearse a grasp and pull on the Panda's kinematic model before doing it.

A parallel gripper can take a handle with its fingers either way round (the TCP turned half a turn
about its approach axis). When the two are about equally far from the hand's current rotation, which
one the arm can reach and hold through the pull depends on its joint limits: one of them can end with
a wrist joint at its limit, the fingers short of the handle or the pull stalling half-way (oven doors,
whose horizontal bar makes the two orders a near tie), or a door whose turn is mostly a roll about
the approach that only wrist joint 7 gives, pinned at its limit part-way (Meta-World's lever door).
:func:`rehearse` plays the opener's moves on :mod:`agents.scripted.panda_kinematics`, the Panda's URDF
model and its ``pd_ee_delta_pose`` controller's own IK: from the measured joint angles, each control
step moves the TCP goal by at most the opener's per-step caps, the controller's IK (which does not know
the joint limits) solves for it and every joint stops at its limit, as the simulated joints do. A
joint pinned at its limit is not made up for by the others (the controller's solution leaves the
pose error to that joint), so the error grows as the pull goes on: the rehearsal counts a pull
waypoint as followed while the TCP is within ``pull_tolerance_m`` and ``pull_tolerance_rad`` of it.
The drive's lag (the arm covers about 40% of a step's joint change within the step) slows the arm but
does not change where it can go, so the rehearsal moves the joints the whole way each step. World
frame, metres, radians.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from agents.scripted.geometry import axis_angle_matrix, clip_norm
from agents.scripted.panda_kinematics import base_in_world, ik_step, pose_error, pose_matrix, tcp_pose


@dataclass(frozen=True)
class Rehearsal:
    """How a rehearsed grasp went: the TCP's distance (m) and rotation error (rad) from the grasp pose
    after the approach, and the share (0..1) of the pull path the TCP followed within the tracking
    tolerances (position and rotation) before it first fell behind."""

    grasp_error_m: float
    grasp_error_rad: float
    pull_share: float


class _Arm:
    """The kinematic arm stepping like the ``pd_ee_delta_pose`` controller under the opener."""

    def __init__(self, q: np.ndarray, tcp_in_world: np.ndarray, max_step_m: float, max_step_rad: float):
        self.q = np.asarray(q, dtype=np.float64).reshape(-1)[:7].copy()
        self.world_to_base = np.linalg.inv(base_in_world(self.q, tcp_in_world))
        self.max_step_m, self.max_step_rad = max_step_m, max_step_rad

    def error(self, goal_in_world: np.ndarray) -> tuple[float, float]:
        """The TCP's position (m) and rotation (rad) error from ``goal_in_world`` (4, 4)."""
        err = pose_error(self.world_to_base @ goal_in_world, tcp_pose(self.q))
        return float(np.linalg.norm(err[:3])), float(np.linalg.norm(err[3:]))

    def step(self, goal_in_world: np.ndarray, turn_only: bool = False) -> None:
        """One control step towards ``goal_in_world`` (4, 4); ``turn_only``: rotate in place."""
        tcp = tcp_pose(self.q)
        err = pose_error(self.world_to_base @ goal_in_world, tcp)
        dp = np.zeros(3) if turn_only else clip_norm(err[:3], self.max_step_m)
        dr = clip_norm(err[3:], self.max_step_rad)
        target = pose_matrix(tcp[:3, 3] + dp, axis_angle_matrix(dr, 1.0) @ tcp[:3, :3])
        self.q = ik_step(self.q, target)

    def move(self, goal_in_world: np.ndarray, max_steps: int, pos_tolerance: float,
             rot_tolerance: float) -> tuple[float, float]:
        """Step towards the goal until within tolerance or ``max_steps``; the final (m, rad) error."""
        for _ in range(max_steps):
            perr, rerr = self.error(goal_in_world)
            if perr < pos_tolerance and rerr < rot_tolerance:
                return perr, rerr
            self.step(goal_in_world)
        return self.error(goal_in_world)


def rehearse(arm_qpos: np.ndarray, tcp_in_world: np.ndarray, rotation: np.ndarray,
             pregrasp: np.ndarray, grasp: np.ndarray, pull_path: list[tuple[np.ndarray, np.ndarray]],
             *, max_step_m: float, max_step_rad: float, rotate_first_above: float,
             rotate_first_steps: int, move_timeout: int, pos_tolerance: float, rot_tolerance: float,
             pull_tolerance_m: float = 0.02, pull_tolerance_rad: float = 0.25,
             steps_per_waypoint: int = 2, clear_at: np.ndarray | None = None) -> Rehearsal:
    """Rehearse turning the hand to ``rotation`` (3, 3), moving to the ``pregrasp`` and ``grasp``
    positions (3,), then following ``pull_path`` (world (position, rotation) waypoints from the grasp
    out, ``steps_per_waypoint`` control steps each), from the arm's joint angles ``arm_qpos`` (7,) rad
    and its TCP pose ``tcp_in_world`` (4, 4). The caps, tolerances and timeouts are the opener's. A
    waypoint is followed when the TCP ends within ``pull_tolerance_m`` m and ``pull_tolerance_rad`` rad
    of it: a hand turned 0.25 rad (15 deg) off the way the part turns twists a bar held across the
    finger pads towards their edge, where it slips out as the lag grows. With ``clear_at`` (3,) the
    hand first moves there unturned (out of a falling door's sweep) and turns there."""
    arm = _Arm(arm_qpos, tcp_in_world, max_step_m, max_step_rad)
    if clear_at is not None:
        arm.move(pose_matrix(clear_at, tcp_in_world[:3, :3]), move_timeout, pos_tolerance, rot_tolerance)
    pregrasp_goal = pose_matrix(pregrasp, rotation)
    for _ in range(rotate_first_steps):
        if arm.error(pregrasp_goal)[1] <= rotate_first_above:
            break
        arm.step(pregrasp_goal, turn_only=True)
    arm.move(pregrasp_goal, move_timeout, pos_tolerance, rot_tolerance)
    grasp_goal = pose_matrix(grasp, rotation)
    grasp_m, grasp_rad = arm.move(grasp_goal, move_timeout, pos_tolerance, rot_tolerance)
    followed = 0
    for position, rot in pull_path:
        goal = pose_matrix(position, rot)
        for _ in range(steps_per_waypoint):
            arm.step(goal)
        perr, rerr = arm.error(goal)
        if perr > pull_tolerance_m or rerr > pull_tolerance_rad:
            break
        followed += 1
    share = followed / len(pull_path) if pull_path else 1.0
    return Rehearsal(grasp_m, grasp_rad, share)
