"""Candidate grasps ranked on the Panda's kinematics: from ManiSkill's rest pose (the base at
(-0.615, 0, 0), unrotated, as on the table scene), a handle the arm can reach ranks above ones it
cannot, however much nearer the hand or better scored they are. World frame, metres, radians."""

from __future__ import annotations

import numpy as np
import pytest
from mani_skill.agents.robots.panda.panda import Panda

from agents.scripted.grasp_reachability import face_on_rotation, pitched_rotation, rank_grasps
from agents.scripted.panda_kinematics import PANDA_LOWER, PANDA_UPPER, pose_error, pose_matrix, tcp_pose
from capt_env.wrappers.grasp_candidates import GraspCandidate

REST = np.asarray(Panda.keyframes["rest"].qpos[:7], dtype=np.float64)  # hand down over the table
BASE = pose_matrix(np.array([-0.615, 0.0, 0.0]), np.eye(3))
TCP = BASE @ tcp_pose(REST)
TOWARDS_ROBOT = np.array([-1.0, 0.0, 0.0])


def _bar(point: np.ndarray, outward: np.ndarray = TOWARDS_ROBOT, axis: tuple[float, ...] = (0.0, 1.0, 0.0),
         width: float = 0.015, clearance: float = 0.06, score: float = 3.5) -> GraspCandidate:
    return GraspCandidate("bar", np.asarray(point, dtype=np.float64), np.asarray(outward, dtype=np.float64),
                          np.asarray(axis, dtype=np.float64), width, clearance, score)


# a horizontal bar on a face turned to the robot, half a metre in front of its base
REACHABLE = _bar(BASE[:3, 3] + [0.5, 0.05, 0.45], score=3.0, clearance=0.04)


def test_a_reachable_handle_ranks_above_a_nearer_unreachable_one() -> None:
    # right under the hand, but on a face turned away from the robot: the hand would point back at it
    behind_the_hand = _bar(TCP[:3, 3] + [0.05, 0.0, 0.05], outward=-TOWARDS_ROBOT, score=3.5, clearance=0.06)
    assert (np.linalg.norm(behind_the_hand.point - TCP[:3, 3])
            < np.linalg.norm(REACHABLE.point - TCP[:3, 3]))
    ranked = rank_grasps([behind_the_hand, REACHABLE], REST, TCP)
    assert [r.candidate for r in ranked] == [REACHABLE, behind_the_hand]
    assert ranked[0].reachable and ranked[0].reason == ""
    assert not ranked[1].reachable and ranked[1].reason.startswith("pre-grasp")


@pytest.mark.parametrize(("point", "outward"), [([1.2, 0.05, 0.45], TOWARDS_ROBOT),
                                               ([-0.5, 0.05, 0.45], -TOWARDS_ROBOT)],
                         ids=["1.2 m away", "behind the base"])
def test_a_handle_out_of_reach_ranks_last_whatever_its_score(point: list[float], outward: np.ndarray) -> None:
    # behind the base: the reachable handle's mirror image, a half turn of joint 1 (limit +-2.90 rad)
    out_of_reach = _bar(BASE[:3, 3] + point, outward=outward, score=3.9, clearance=0.06)
    ranked = rank_grasps([out_of_reach, REACHABLE], REST, TCP)
    assert [r.reachable for r in ranked] == [True, False] and ranked[0].candidate is REACHABLE
    assert ranked[1].q_grasp is None and "short" in ranked[1].reason


def test_a_reached_grasp_puts_the_tcp_on_the_handle_inside_the_joint_limits() -> None:
    ranked = rank_grasps([REACHABLE], REST, TCP)[0]
    assert ranked.q_grasp is not None and ranked.q_pregrasp is not None
    pregrasp = REACHABLE.point + 0.1 * TOWARDS_ROBOT
    for q, point in ((ranked.q_grasp, REACHABLE.point), (ranked.q_pregrasp, pregrasp)):
        err = pose_error(pose_matrix(point, ranked.rotation), BASE @ tcp_pose(q))
        assert np.linalg.norm(err[:3]) < 0.005 and np.linalg.norm(err[3:]) < 0.05
        assert np.all(q > PANDA_LOWER + 0.05) and np.all(q < PANDA_UPPER - 0.05)
    # the hand comes at the face (pitched down as the opener does), the fingers close across the bar
    approach, closing = ranked.rotation[:, 2], ranked.rotation[:, 1]
    assert float(approach @ -TOWARDS_ROBOT) > np.cos(0.6) and approach[2] < 0.0
    assert abs(float(closing @ REACHABLE.bar_axis)) < 1e-9


def test_face_on_rotation_approaches_along_the_normal_and_closes_across_the_bar() -> None:
    diagonal = _bar(REACHABLE.point, axis=(0.0, np.sqrt(0.5), np.sqrt(0.5)))
    rot = face_on_rotation(diagonal, TCP[:3, :3])
    np.testing.assert_allclose(rot[:, 2], -TOWARDS_ROBOT, atol=1e-12)
    assert abs(float(rot[:, 1] @ diagonal.bar_axis)) < 1e-12
    np.testing.assert_allclose(rot.T @ rot, np.eye(3), atol=1e-12)
    assert np.linalg.det(rot) == pytest.approx(1.0)
    pitched = pitched_rotation(diagonal, TCP[:3, :3])
    assert pitched[2, 2] < -0.5  # turned down, still a rotation
    np.testing.assert_allclose(pitched.T @ pitched, np.eye(3), atol=1e-12)


def test_among_reachable_grasps_one_that_fits_the_gripper_comes_first_then_the_score() -> None:
    too_wide = _bar(REACHABLE.point + [0.0, 0.0, -0.05], width=0.09, score=3.9)
    cramped = _bar(REACHABLE.point + [0.0, 0.05, 0.0], clearance=0.01, score=3.8)
    better = _bar(REACHABLE.point + [0.0, -0.05, 0.0], score=3.4)
    ranked = rank_grasps([too_wide, cramped, REACHABLE, better], REST, TCP)
    assert all(r.reachable for r in ranked)
    assert [r.candidate for r in ranked] == [better, REACHABLE, too_wide, cramped]
    assert [r.fits for r in ranked] == [True, True, False, False]
