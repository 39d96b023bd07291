"""Residual PPO on the scripted opener: the composed action, the wrapper, and a saved residual model."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest
from gymnasium.utils.env_checker import check_env

import capt_env  # noqa: F401
from agents.ppo.config import PPOTrainConfig
from agents.ppo.policy import PPOPolicy
from agents.ppo.residual import (
    RESIDUAL_OBSERVATION_SIZE,
    ResidualComposer,
    ScriptedResidualWrapper,
    residual_observation_space,
)
from agents.ppo.train import train_ppo
from agents.scripted.opener import Phase, ScriptedOpener
from capt_common.typed_yaml import from_dict
from capt_env.env_factory import make_env
from capt_env.wrappers.joint_observation import OBSERVATION_SIZE

SEED = 5


@pytest.fixture(scope="module")
def first_obs() -> tuple[np.ndarray, dict]:
    env = make_env("drawer_cabinet", {"source": "oracle"}, max_episode_steps=30)
    try:
        return env.reset(seed=SEED)
    finally:
        env.close()


def test_composer_adds_the_scaled_clipped_residual(first_obs: tuple[np.ndarray, dict]) -> None:
    obs, info = first_obs
    composer = ResidualComposer(scale=0.2)
    ext = composer.observe(obs, info)
    assert ext.shape == (RESIDUAL_OBSERVATION_SIZE,) and ext.dtype == np.float32
    assert residual_observation_space().contains(ext)
    np.testing.assert_array_equal(ext[:OBSERVATION_SIZE], obs)
    base = ScriptedOpener().act(obs, info)
    np.testing.assert_allclose(ext[OBSERVATION_SIZE:OBSERVATION_SIZE + 7], base, atol=1e-6)
    phase = ext[OBSERVATION_SIZE + 7:]
    assert phase.sum() == 1.0 and phase[list(Phase).index(Phase.PREGRASP)] == 1.0

    np.testing.assert_allclose(composer.compose(np.zeros(7)), base, atol=1e-6)
    residual = np.array([1.0, -0.5, 3.0, 0.0, 0.0, 0.0, -9.0])  # out-of-range entries are clipped
    expected = np.clip(base + 0.2 * np.clip(residual, -1, 1), -1, 1)
    np.testing.assert_allclose(composer.compose(residual), expected, atol=1e-6)
    assert np.all(np.abs(composer.compose(np.full(7, 1e3))) <= 1.0)


def test_composer_rejects_bad_input(first_obs: tuple[np.ndarray, dict]) -> None:
    with pytest.raises(ValueError, match="scale"):
        ResidualComposer(scale=0.0)
    with pytest.raises(ValueError, match="flat"):
        ResidualComposer(scale=0.2).observe(first_obs[0][:10])


def test_zero_residual_replays_the_scripted_opener() -> None:
    """With a zero residual the wrapped env follows the scripted opener step for step."""
    steps = 25
    env = make_env("drawer_cabinet", {"source": "oracle"}, max_episode_steps=steps)
    try:
        opener = ScriptedOpener()
        obs, info = env.reset(seed=SEED)
        opener.reset()
        scripted_tcp = []
        for _ in range(steps):
            obs, *_, info = env.step(opener.act(obs, info))
            scripted_tcp.append(obs[18:25].copy())  # TCP position and quaternion

        wrapped = ScriptedResidualWrapper(env, scale=0.2)
        ext, info = wrapped.reset(seed=SEED)
        residual_tcp = []
        for _ in range(steps):
            ext, *_, info = wrapped.step(np.zeros(7, np.float32))
            residual_tcp.append(ext[18:25].copy())
            assert info["base_action"].shape == (7,)
    finally:
        env.close()
    np.testing.assert_allclose(np.array(residual_tcp), np.array(scripted_tcp), atol=1e-5)
    # the opener did move the hand (it first turns it in place towards the grasp orientation)
    assert np.linalg.norm(scripted_tcp[-1] - scripted_tcp[0]) > 0.05


def test_wrapper_passes_the_env_checker() -> None:
    # perception every 2nd step: the checker compares infos of one step, and a latency is a timing
    env = ScriptedResidualWrapper(make_env("drawer_cabinet", {"source": "oracle", "every_k_steps": 2},
                                           max_episode_steps=10),
                                  scale=0.2)
    try:
        assert env.observation_space.shape == (RESIDUAL_OBSERVATION_SIZE,)
        check_env(env, skip_render_check=True)
    finally:
        env.close()


def test_saved_residual_model_runs_with_the_opener(tmp_path: Path,
                                                   first_obs: tuple[np.ndarray, dict]) -> None:
    config = from_dict(PPOTrainConfig, {
        "category": "drawer_cabinet", "perception": {"source": "noisy_oracle", "every_k_steps": 2},
        "n_envs": 1, "total_timesteps": 32, "seed": 1, "max_episode_steps": 16,
        "residual": {"enabled": True, "scale": 0.3},
        "ppo": {"n_steps": 32, "batch_size": 16, "n_epochs": 1, "net_arch": [16], "log_std_init": -1.0}})
    train_ppo(config, tmp_path / "run")
    policy = PPOPolicy.load(tmp_path / "run" / "final.zip")
    assert policy.residual is not None and policy.residual.scale == 0.3
    assert policy.model.observation_space.shape == (RESIDUAL_OBSERVATION_SIZE,)

    obs, info = first_obs
    policy.reset()
    action = policy.act(obs, info)
    # by hand: the opener's action plus 0.3 x the model's (normalised-input) action
    composer = ResidualComposer(scale=0.3)
    ext = policy.obs_norm.normalize_obs(composer.observe(obs, info)).astype(np.float32)
    raw, _ = policy.model.predict(ext, deterministic=True)
    np.testing.assert_allclose(action, composer.compose(raw), atol=1e-6)
    assert np.exp(policy.model.policy.log_std.detach().numpy()).max() < 0.5  # log_std_init -1

    # without its run config the model cannot be run correctly: a clear error
    (tmp_path / "run" / "config.yaml").unlink()
    with pytest.raises(ValueError, match="residual"):
        PPOPolicy.load(tmp_path / "run" / "final.zip")


@pytest.mark.parametrize(("category", "seed"), [("drawer_cabinet", 0), ("laptop", 3)])
def test_shipped_policy_opens_an_unseen_instance(category: str, seed: int) -> None:
    """A shipped residual policy loads with its opener and opens a test-split instance with oracle
    perception (each did in its 50-episode benchmark: benchmarks/rollout_ppo_oracle*.json)."""
    from agents.ppo.policies import shipped_policy
    from agents.scripted.rollout import run_episode

    policy = PPOPolicy.load(shipped_policy(category))
    assert policy.residual is not None and policy.obs_norm is not None
    env = make_env(category, {"source": "oracle", "every_k_steps": 5})
    try:
        result = run_episode(env, policy, seed=seed)
    finally:
        env.close()
    assert result.success and result.open_fraction >= 0.75


def test_features_constant_in_training_are_pinned(first_obs: tuple[np.ndarray, dict]) -> None:
    """The laptop's policy was trained with oracle confidence 1; CAPT's lower confidence must not
    change its action (unpinned, VecNormalize would turn 0.6 into -10 standard deviations)."""
    from agents.ppo.policies import shipped_policy
    from capt_env.wrappers.joint_observation import observation_layout

    policy = PPOPolicy.load(shipped_policy("laptop"))
    confidence = observation_layout()["confidence"]
    assert confidence.start in policy._pinned
    obs, info = first_obs
    actions = []
    for value in (1.0, 0.6):
        x = obs.copy()
        x[confidence] = value
        policy.reset()
        actions.append(policy.act(x, info))
    np.testing.assert_array_equal(actions[0], actions[1])
    # a feature that did vary (the TCP position) still moves the action
    x = obs.copy()
    x[observation_layout()["tcp_pose"].start] += 0.05
    policy.reset()
    assert not np.array_equal(policy.act(x, info), actions[0])


def test_unknown_shipped_policy_names_the_shipped_ones() -> None:
    from agents.ppo.policies import shipped_policy

    with pytest.raises(FileNotFoundError, match="drawer_cabinet"):
        shipped_policy("toaster")
