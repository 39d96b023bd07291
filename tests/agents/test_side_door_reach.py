"""A side door swung far round stays within the Panda's reach: the pull of a hand closed across a
level bar (a lever) pitches the hand down about the bar as the door turns (``side_door.pull_roll``),
and a hand closed across an upright bar lags the door's turn (``side_door.upright_bar_follow``), so
that the wrist stays over the handle instead of out beyond the door. Pure kinematics (the
controller's IK stepped along the pull), no simulator; the door is placed as the task places
Meta-World's lever door in front of the robot (base at (-0.615, 0, 0)). World frame, metres,
radians."""

from __future__ import annotations

import numpy as np
import pytest
from mani_skill.agents.robots.panda.panda import Panda

from agents.scripted import ScriptedOpenerConfig
from agents.scripted.config import with_options
from agents.scripted.geometry import axis_angle_matrix
from agents.scripted.grasp_pose import quarter_turn
from agents.scripted.panda_kinematics import ik_step, pose_error, pose_matrix, tcp_pose
from agents.scripted.part_strategies import SideDoor
from capt_env.wrappers.estimate import JointAxisEstimate

REST = np.asarray(Panda.keyframes["rest"].qpos[:7], dtype=np.float64)
BASE = np.array([-0.615, 0.0, 0.0])
# a door hinged at its far left (seen from the robot), opening towards the robot; its handle 37 cm
# from the hinge and 12 cm off the door's face (a lever on its post)
HINGE = np.array([0.318, 0.177, 0.151])
HINGE_AXIS = np.array([0.0, 0.0, -1.0])  # pointing down: +state opens the door towards the robot
HANDLE = np.array([0.128, -0.144, 0.151])
SUCCESS_ANGLE = 1.5  # 0.75 of the door's 2 rad range


def _pull_error(cfg: ScriptedOpenerConfig, angle: float, quarter: bool) -> float:
    """How far (m) the TCP ends from the pull's goal with the door at ``angle`` rad, the arm having
    followed the pull from the grasp in 0.05 rad steps, three controller steps each."""
    door = SideDoor(cfg)
    est = JointAxisEstimate("revolute", HINGE_AXIS, HINGE, 0.0, HANDLE)
    r0 = door.grasp_rotation(est, tcp_pose(REST)[:3, :3])
    if quarter:
        r0 = quarter_turn(r0, r0)
    q = REST.copy()
    start = tcp_pose(q)
    for share in np.linspace(0.1, 1.0, 10):  # in to the grasp along a straight line
        for _ in range(3):
            q = ik_step(q, pose_matrix(start[:3, 3] + share * (HANDLE - BASE - start[:3, 3]), r0))
    err = np.zeros(6)
    for turned in np.arange(0.05, angle + 1e-9, 0.05):
        turn = axis_angle_matrix(HINGE_AXIS, turned)
        hand = door.pulling_rotation(est, False, r0, HINGE_AXIS, turned, turned)
        goal = pose_matrix(HINGE + turn @ (HANDLE - HINGE) - BASE, hand)
        for _ in range(3):
            q = ik_step(q, goal)
        err = pose_error(goal, tcp_pose(q))
    return float(np.linalg.norm(err[:3]))


@pytest.mark.parametrize("quarter", [False, True], ids=["across_an_upright_bar", "across_a_lever"])
def test_a_side_door_swung_to_its_success_angle_stays_within_reach(quarter: bool) -> None:
    cfg = ScriptedOpenerConfig()
    assert _pull_error(cfg, SUCCESS_ANGLE, quarter) < 0.005
    # the hand kept square to the door: its wrist ends out beyond the door and the arm falls short
    square = with_options(cfg, side_door__pull_roll=0.0, side_door__upright_bar_follow=1.0)
    assert _pull_error(square, SUCCESS_ANGLE, quarter) > 0.015
