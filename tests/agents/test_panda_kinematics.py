"""The Panda's kinematic model is the simulated arm's (its TCP, its joint limits, its controller's IK),
and a rehearsal tells a reachable grasp and pull from one that needs a joint past its limit."""

from __future__ import annotations

import numpy as np
import pytest
import torch

import capt_env  # noqa: F401
from agents.scripted.geometry import axis_angle_matrix, quat_to_matrix
from agents.scripted.grasp_rehearsal import rehearse
from agents.scripted.panda_kinematics import (
    PANDA_LOWER,
    PANDA_UPPER,
    base_in_world,
    ik_step,
    jacobian,
    pose_error,
    pose_matrix,
    solve_ik,
    tcp_pose,
)
from capt_env.env_factory import make_env
from capt_env.wrappers.joint_observation import decode_observation

_HOME = np.array([0.0, 0.3, 0.0, -2.0, 0.0, 2.3, 0.8])  # near ManiSkill's reset pose, hand down
_Z = np.array([0.0, 0.0, 1.0])


@pytest.fixture(scope="module")
def env():
    env = make_env("oven", {"source": "oracle"}, obs_mode="state")
    env.reset(seed=3)
    yield env
    env.close()


def _matrix(pose) -> np.ndarray:
    """(4, 4) of a ManiSkill batched Pose (first sub-scene)."""
    return pose_matrix(pose.p[0].cpu().numpy(), quat_to_matrix(pose.q[0].cpu().numpy()))


def _observed(obs) -> tuple[np.ndarray, np.ndarray]:
    proprio, _ = decode_observation(obs)
    q = np.asarray(proprio["qpos"], dtype=np.float64).reshape(-1)[:7]
    tcp = pose_matrix(np.asarray(proprio["tcp_pose"][:3]), quat_to_matrix(proprio["tcp_pose"][3:7]))
    return q, tcp


def test_the_joint_limits_are_the_simulated_robots(env) -> None:
    limits = env.unwrapped.agent.robot.get_qlimits()[0, :7].cpu().numpy()
    np.testing.assert_allclose(PANDA_LOWER, limits[:, 0], atol=1e-6)
    np.testing.assert_allclose(PANDA_UPPER, limits[:, 1], atol=1e-6)


def test_the_tcp_is_where_the_simulator_puts_it_in_random_arm_poses(env) -> None:
    robot, agent = env.unwrapped.agent.robot, env.unwrapped.agent
    rng = np.random.default_rng(0)
    for _ in range(6):
        q = rng.uniform(PANDA_LOWER + 0.05, PANDA_UPPER - 0.05)
        robot.set_qpos(torch.tensor(np.r_[q, 0.04, 0.04], dtype=torch.float32)[None])
        simulated = np.linalg.inv(_matrix(robot.pose)) @ _matrix(agent.tcp.pose)
        err = pose_error(simulated, tcp_pose(q))
        assert np.linalg.norm(err[:3]) < 1e-5 and np.linalg.norm(err[3:]) < 1e-5


def test_the_model_puts_the_base_where_the_simulator_has_it_in_any_arm_pose(env) -> None:
    # the base is fixed: every (joint angles, simulated TCP pose) pair must give the same base pose
    rng = np.random.default_rng(0)
    obs, _ = env.reset(seed=3)
    for _ in range(8):
        q, tcp = _observed(obs)
        base = base_in_world(q, tcp)
        # ManiSkill's table scene: base at (-0.615, 0, 0), unrotated
        np.testing.assert_allclose(base[:3, 3], [-0.615, 0.0, 0.0], atol=5e-4)
        np.testing.assert_allclose(base[:3, :3], np.eye(3), atol=1e-3)
        obs, *_ = env.step(rng.uniform(-1.0, 1.0, 7).astype(np.float32))


def test_the_ik_is_the_one_the_delta_pose_controller_solves(env) -> None:
    # each step the controller solves for its target pose (base frame) from the joint angles it
    # had; the model's solve gives the same joint targets, and fails (the controller then holds the
    # joints where they are) where the controller's fails: twice in these full-scale random steps
    rng = np.random.default_rng(0)
    obs, _ = env.reset(seed=3)
    controller = env.unwrapped.agent.controller.controllers["arm"]  # (a reset may build it anew)
    failed = 0
    for _ in range(16):
        q, _ = _observed(obs)
        obs, *_ = env.step(rng.uniform(-1.0, 1.0, 7).astype(np.float32))
        solved = solve_ik(q, _matrix(controller._target_pose))
        failed += solved is None
        expected = controller._target_qpos[0, :7].cpu().numpy()
        np.testing.assert_allclose(q if solved is None else solved, expected, atol=1e-5)
    assert failed == 2


def test_the_jacobian_matches_finite_differences() -> None:
    q = _HOME + np.array([0.1, -0.2, 0.3, 0.1, -0.4, 0.2, 0.5])
    jac, tcp = jacobian(q)
    np.testing.assert_allclose(tcp, tcp_pose(q))
    eps = 1e-6
    for i in range(7):
        dq = np.zeros(7)
        dq[i] = eps
        d = pose_error(tcp_pose(q + dq), tcp_pose(q - dq)) / (2 * eps)
        np.testing.assert_allclose(jac[:, i], d, atol=1e-6)


def test_ik_round_trip_from_nearby_joint_angles() -> None:
    rng = np.random.default_rng(2)
    for _ in range(5):
        q = rng.uniform(PANDA_LOWER + 0.3, PANDA_UPPER - 0.3)
        target = tcp_pose(q)
        solved = solve_ik(q + rng.uniform(-0.1, 0.1, 7), target)
        assert solved is not None
        err = pose_error(target, tcp_pose(solved))
        assert np.linalg.norm(err[:3]) < 1e-4 and np.linalg.norm(err[3:]) < 1e-4


def test_a_joint_stops_at_its_limit_and_the_others_do_not_make_up_for_it() -> None:
    # a turn about the approach past joint 7's limit: the controller's IK turns joint 7 alone (the
    # solution would put it past the limit), joint 7 stops there and the rotation stays short
    at_limit = _HOME.copy()
    at_limit[6] = PANDA_UPPER[6] - 0.05
    start = tcp_pose(at_limit)
    beyond = pose_matrix(start[:3, 3], start[:3, :3] @ axis_angle_matrix(_Z, 0.1))
    unlimited = solve_ik(at_limit, beyond)
    assert unlimited is not None and unlimited[6] > PANDA_UPPER[6]
    q = ik_step(at_limit, beyond)
    assert q[6] == PANDA_UPPER[6] and np.all(q >= PANDA_LOWER) and np.all(q <= PANDA_UPPER)
    np.testing.assert_allclose(q[:6], unlimited[:6])
    assert np.linalg.norm(pose_error(beyond, tcp_pose(q))[3:]) == pytest.approx(0.05, abs=0.01)


def test_bad_joint_vectors_are_rejected() -> None:
    with pytest.raises(ValueError, match="7 arm joints"):
        tcp_pose(np.zeros(9))


_MOVES = {"max_step_m": 0.03, "max_step_rad": 0.15, "rotate_first_above": 0.4, "rotate_first_steps": 25,
          "move_timeout": 60, "pos_tolerance": 0.012, "rot_tolerance": 0.12}


def _rehearse_turn(q: np.ndarray, angle: float):
    """Rehearse a grasp 10 cm ahead of the TCP, turned ``angle`` rad about the approach axis, and a
    10 cm straight pull back."""
    start = tcp_pose(q)
    tcp_world = start.copy()  # base at the world origin
    rotation = start[:3, :3] @ axis_angle_matrix(_Z, angle)
    approach = rotation[:, 2]
    grasp = start[:3, 3] + 0.1 * approach
    path = [(grasp - d * approach, rotation) for d in np.arange(0.01, 0.101, 0.01)]
    return rehearse(q, tcp_world, rotation, grasp - 0.05 * approach, grasp, path, **_MOVES)


def test_a_rehearsal_tells_a_reachable_finger_order_from_one_past_the_wrist_limit() -> None:
    q = _HOME.copy()
    q[6] = PANDA_UPPER[6] - 0.3  # joint 7 can turn 0.3 rad further one way and 5.5 the other
    near = _rehearse_turn(q, -1.5)
    assert near.grasp_error_m < 0.012 and near.grasp_error_rad < 0.12 and near.pull_share == 1.0
    far = _rehearse_turn(q, 1.5)  # the same approach, the fingers turned the other way
    assert far.grasp_error_rad > 0.24  # the wrist stopped at its limit


def _rehearse_rolling_pull(q: np.ndarray, turn: float, **tolerances: float):
    """Rehearse a grasp 10 cm ahead of the TCP, then a pull that backs off 0.5 cm and rolls the hand
    ``turn`` x 0.05 rad about its approach per waypoint, 20 waypoints (a door whose turn is a roll
    about the approach, as Meta-World's lever door under a pitched hand); ``tolerances``: the
    rehearsal's pull tolerances."""
    start = tcp_pose(q)
    rotation = start[:3, :3]
    approach = rotation[:, 2]
    grasp = start[:3, 3] + 0.1 * approach
    path = [(grasp - 0.005 * i * approach, rotation @ axis_angle_matrix(_Z, turn * 0.05 * i))
            for i in range(1, 21)]
    return rehearse(q, start.copy(), rotation, grasp - 0.05 * approach, grasp, path, **_MOVES,
                    **tolerances)


def test_a_pull_that_rolls_the_wrist_past_its_limit_fails_the_rehearsal() -> None:
    # the grasp is reached either way; rolling towards joint 7's limit (0.3 rad away) pins it there
    # and the hand falls behind the roll while its position still follows: the rehearsal stops
    # counting when the rotation error passes its tolerance
    q = _HOME.copy()
    q[6] = PANDA_UPPER[6] - 0.3
    towards = _rehearse_rolling_pull(q, 1.0)
    away = _rehearse_rolling_pull(q, -1.0)
    assert towards.grasp_error_m < 0.012 and towards.grasp_error_rad < 0.12
    assert away.pull_share == 1.0
    # pinned after 6 waypoints (0.3 rad), 0.25 rad behind after about 5 more
    assert 0.4 <= towards.pull_share <= 0.7
    # counted by position alone, the pinned wrist would pass
    positions = _rehearse_rolling_pull(q, 1.0, pull_tolerance_rad=np.inf)
    assert positions.pull_share == 1.0

