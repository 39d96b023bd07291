"""The wrapped env is a valid Gymnasium env with the documented observation, and the perception
sources behave as configured (oracle = ground truth, noisy oracle = noise of the set size)."""

from __future__ import annotations

import gymnasium as gym
import numpy as np
import pytest
from gymnasium.utils.env_checker import check_env

import capt_env  # noqa: F401  (registers the ids)
from capt_common.typed_yaml import ConfigError, from_dict
from capt_env.wrappers import CaptObservationWrapper, observation_layout
from capt_env.wrappers.config import NoiseConfig
from capt_env.wrappers.joint_observation import OBSERVATION_SIZE, decode_observation
from capt_env.wrappers.perception_sources import NoisyOracleSource, ground_truth_estimate

TASK = {"split": "test", "object_xy": (0.3, 0.0)}


def _env(config: dict, obs_mode: str = "state") -> CaptObservationWrapper:
    base = gym.make("CaptOpenDrawerCabinet-v0", obs_mode=obs_mode, control_mode="pd_ee_delta_pose", task=TASK)
    return CaptObservationWrapper(base, config)


@pytest.mark.parametrize("obs_format", ["flat", "dict"])
def test_check_env_and_declared_space(obs_format: str) -> None:
    env = _env({"source": "noisy_oracle", "obs_format": obs_format, "every_k_steps": 1})
    try:
        check_env(env, skip_render_check=True)
        obs, info = env.reset(seed=3)
        assert env.observation_space.contains(obs)
        if obs_format == "flat":
            assert env.observation_space.shape == (OBSERVATION_SIZE,) == (max(s.stop for s in
                                                                             observation_layout().values()),)
            assert obs.dtype == np.float32
        ran = []
        for _ in range(4):
            obs, _, _, _, info = env.step(np.zeros(7, np.float32))
            ran.append(info["perception_ran"])
            assert "perception_latency_ms" not in info and env.last_perception_latency_ms >= 0.0
        assert ran == [True, True, True, True]
    finally:
        env.close()


def test_oracle_observation_is_ground_truth() -> None:
    env = _env({"source": "oracle"})
    try:
        obs, info = env.reset(seed=1)
        _, est = decode_observation(obs)
        k = int(info["target_joint"])
        np.testing.assert_allclose(est.direction, info["joint_axis"][k], atol=1e-5)
        np.testing.assert_allclose(est.grasp_point, info["grasp_point"], atol=1e-5)
        # the pivot lies on the true axis and is the point of it closest to the grasp point
        rel = est.pivot - info["joint_pivot"][k]
        assert np.linalg.norm(np.cross(rel, info["joint_axis"][k])) < 1e-5
        assert abs((info["grasp_point"] - est.pivot) @ info["joint_axis"][k]) < 1e-5
        tcp = env.unwrapped.agent.tcp.pose.raw_pose[0].numpy()
        np.testing.assert_allclose(obs[observation_layout()["tcp_pose"]], tcp, atol=1e-6)
    finally:
        env.close()


def test_noisy_oracle_noise_has_the_configured_magnitude() -> None:
    info = {"target_joint": 0, "joint_type": np.array([0]), "joint_axis": np.array([[0.0, 0.0, 1.0]]),
            "joint_pivot": np.array([[0.1, 0.2, 0.0]]), "joint_state": np.array([0.3]),
            "grasp_point": np.array([0.4, 0.2, 0.3])}
    noise = NoiseConfig(direction_rad=0.1, pivot_m=0.02, state=0.05, grasp_m=0.0)
    src = NoisyOracleSource(noise, seed=0)
    gt = ground_truth_estimate(info)
    est = [src.estimate(None, info) for _ in range(3000)]
    angles = np.array([np.arccos(np.clip(e.direction @ gt.direction, -1, 1)) for e in est])
    # |N(0, s)| has mean s * sqrt(2 / pi)
    assert abs(angles.mean() - 0.1 * np.sqrt(2 / np.pi)) < 0.005
    states = np.array([e.state for e in est]) - 0.3
    assert abs(states.std() - 0.05) < 0.004 and abs(states.mean()) < 0.004
    # off-axis pivot error: the 2 of 3 Gaussian components perpendicular to the axis survive
    off = np.array([np.linalg.norm(np.cross(e.pivot - gt.pivot, gt.direction)) for e in est])
    assert abs(np.sqrt((off ** 2).mean()) - 0.02 * np.sqrt(2)) < 0.004
    np.testing.assert_allclose([e.grasp_point for e in est], np.tile(gt.grasp_point, (3000, 1)))


def test_noisy_oracle_fixed_offset_has_exact_sizes_held_for_the_episode() -> None:
    from perception.metrics import line_distance

    info = {"target_joint": 0, "joint_type": np.array([0]), "joint_axis": np.array([[0.0, 0.0, 1.0]]),
            "joint_pivot": np.array([[0.1, 0.2, 0.0]]), "joint_state": np.array([0.3]),
            "grasp_point": np.array([0.4, 0.2, 0.3])}
    gt = ground_truth_estimate(info)
    tilted = NoisyOracleSource(NoiseConfig(model="fixed_offset", direction_rad=0.2, pivot_m=0.0, state=0.1,
                                           grasp_m=0.03), seed=4)
    first = [tilted.estimate(None, info) for _ in range(5)]
    for e in first:  # the same error at every estimate of the episode
        np.testing.assert_allclose(e.direction, first[0].direction, atol=1e-12)
        np.testing.assert_allclose(e.grasp_point, first[0].grasp_point, atol=1e-12)
    assert np.arccos(np.clip(first[0].direction @ gt.direction, -1, 1)) == pytest.approx(0.2, abs=1e-9)
    assert abs(first[0].state - 0.3) == pytest.approx(0.1, abs=1e-12)
    assert np.linalg.norm(first[0].grasp_point - gt.grasp_point) == pytest.approx(0.03, abs=1e-12)
    tilted.reset()  # a new episode draws a new tilt direction of the same size
    again = tilted.estimate(None, info)
    assert np.linalg.norm(again.direction - first[0].direction) > 1e-3
    assert np.arccos(np.clip(again.direction @ gt.direction, -1, 1)) == pytest.approx(0.2, abs=1e-9)
    # a pivot offset alone moves the line parallel to itself, exactly pivot_m off the true one
    shifted = NoisyOracleSource(NoiseConfig(model="fixed_offset", direction_rad=0.0, pivot_m=0.04, state=0.0,
                                            grasp_m=0.0), seed=1).estimate(None, info)
    np.testing.assert_allclose(shifted.direction, gt.direction, atol=1e-12)
    off = line_distance(shifted.direction, shifted.pivot, gt.direction, gt.pivot)
    assert off == pytest.approx(0.04, abs=1e-9)
    with pytest.raises(ConfigError, match="model"):
        from_dict(NoiseConfig, {"model": "uniform"})


def test_noisy_oracle_grasp_outward_bias_moves_the_grasp_point_away_from_the_joint() -> None:
    # hinge along z through (0.1, 0.2): the grasp point (0.4, 0.2, 0.3) lies 0.3 m out along +x
    info = {"target_joint": 0, "joint_type": np.array([0]), "joint_axis": np.array([[0.0, 0.0, 1.0]]),
            "joint_pivot": np.array([[0.1, 0.2, 0.0]]), "joint_state": np.array([0.3]),
            "grasp_point": np.array([0.4, 0.2, 0.3])}
    quiet = {"direction_rad": 0.0, "pivot_m": 0.0, "state": 0.0, "grasp_m": 0.0}
    est = NoisyOracleSource(NoiseConfig(**quiet, grasp_outward_m=0.012)).estimate(None, info)
    np.testing.assert_allclose(est.grasp_point, [0.412, 0.2, 0.3], atol=1e-12)
    # a prismatic part: along its opening direction
    info["joint_type"] = np.array([1])
    est = NoisyOracleSource(NoiseConfig(**quiet, grasp_outward_m=0.012)).estimate(None, info)
    np.testing.assert_allclose(est.grasp_point, [0.4, 0.2, 0.312], atol=1e-12)
    with pytest.raises(ConfigError, match="grasp_outward_m"):
        from_dict(NoiseConfig, {"grasp_outward_m": -0.01})


def test_capt_source_needs_a_point_cloud() -> None:
    base = gym.make("CaptOpenDrawerCabinet-v0", obs_mode="state", task=TASK)
    with pytest.raises(ValueError, match="pointcloud"):
        CaptObservationWrapper(base, {"source": "capt", "checkpoint": "missing.pt"})
    base.close()
