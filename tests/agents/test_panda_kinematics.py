"""The Panda's kinematic model matches the simulated arm, and a rehearsal tells a reachable grasp from
one beyond a joint limit."""

from __future__ import annotations

import numpy as np
import pytest

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
    tcp_pose,
)
from capt_env.env_factory import make_env
from capt_env.wrappers.joint_observation import decode_observation

_HOME = np.array([0.0, 0.3, 0.0, -2.0, 0.0, 2.3, 0.8])  # near ManiSkill's reset pose, hand down


def test_the_model_puts_the_base_where_the_simulator_has_it_in_any_armpose_matrix() -> None:
    # the base is fixed: every (joint angles, simulated TCP pose) pair must give the same base pose
    env = make_env("oven", {"source": "oracle"}, obs_mode="state")
    rng = np.random.default_rng(0)
    obs, _ = env.reset(seed=3)
    bases = []
    for _ in range(12):
        proprio, _ = decode_observation(obs)
        q = np.asarray(proprio["qpos"]).reshape(-1)[:7]
        tcp = pose_matrix(np.asarray(proprio["tcp_pose"][:3]), quat_to_matrix(proprio["tcp_pose"][3:7]))
        bases.append(base_in_world(q, tcp))
        obs, *_ = env.step(rng.uniform(-1.0, 1.0, 7).astype(np.float32))
    env.close()
    moved = np.ptp([b[:3, 3] for b in bases], axis=0)
    assert np.all(moved < 5e-4)  # m
    for b in bases:  # ManiSkill's table scene: base at (-0.615, 0, 0), unrotated
        np.testing.assert_allclose(b[:3, 3], [-0.615, 0.0, 0.0], atol=5e-4)
        np.testing.assert_allclose(b[:3, :3], np.eye(3), atol=1e-3)


def test_the_jacobian_matches_finite_differences() -> None:
    q = _HOME + np.array([0.1, -0.2, 0.3, 0.1, -0.4, 0.2, 0.5])
    jac, tcp = jacobian(q)
    eps = 1e-6
    for i in range(7):
        dq = np.zeros(7)
        dq[i] = eps
        d = pose_error(tcp_pose(q + dq), tcp) / eps
        np.testing.assert_allclose(jac[:, i], d, atol=1e-4)


def test_ik_reaches_a_nearby_pose_and_keeps_the_joints_in_their_limits() -> None:
    target = tcp_pose(_HOME + np.array([0.2, 0.1, -0.1, 0.15, 0.2, -0.1, 0.3]))
    q = _HOME.copy()
    for _ in range(10):
        q = ik_step(q, target)
    err = pose_error(target, tcp_pose(q))
    assert np.linalg.norm(err[:3]) < 1e-3 and np.linalg.norm(err[3:]) < 1e-2
    # a target beyond joint 7's limit: the wrist stops there and the error stays
    at_limit = _HOME.copy()
    at_limit[6] = PANDA_UPPER[6] - 0.05
    start = tcp_pose(at_limit)
    beyond = pose_matrix(start[:3, 3], start[:3, :3] @ axis_angle_matrix(np.array([0.0, 0.0, 1.0]), 1.5))
    q = at_limit
    for _ in range(20):
        q = ik_step(q, beyond)
    assert np.all(q >= PANDA_LOWER) and np.all(q <= PANDA_UPPER)
    assert np.linalg.norm(pose_error(beyond, tcp_pose(q))[3:]) > 0.3


def test_bad_joint_vectors_are_rejected() -> None:
    with pytest.raises(ValueError, match="7 arm joints"):
        tcp_pose(np.zeros(9))


def _rehearse_turn(q: np.ndarray, angle: float):
    """Rehearse a grasp 10 cm ahead of the TCP, turned ``angle`` rad about the approach axis, and a
    10 cm straight pull back."""
    start = tcp_pose(q)
    tcp_world = start.copy()  # base at the world origin
    rotation = start[:3, :3] @ axis_angle_matrix(np.array([0.0, 0.0, 1.0]), angle)
    approach = rotation[:, 2]
    grasp = start[:3, 3] + 0.1 * approach
    path = [(grasp - d * approach, rotation) for d in np.arange(0.01, 0.101, 0.01)]
    return rehearse(q, tcp_world, rotation, grasp - 0.05 * approach, grasp, path, max_step_m=0.03,
                    max_step_rad=0.15, rotate_first_above=0.4, rotate_first_steps=25, move_timeout=60,
                    pos_tolerance=0.012, rot_tolerance=0.12)


def test_a_rehearsal_tells_a_reachable_finger_order_from_one_past_the_wrist_limit() -> None:
    q = _HOME.copy()
    q[6] = PANDA_UPPER[6] - 0.3  # joint 7 can turn 0.3 rad further one way and 5.5 the other
    near = _rehearse_turn(q, -1.5)
    assert near.grasp_error_m < 0.012 and near.grasp_error_rad < 0.12 and near.pull_share == 1.0
    far = _rehearse_turn(q, 1.5)  # the same approach, the fingers turned the other way
    assert far.grasp_error_rad > 0.24  # the wrist stopped at its limit
