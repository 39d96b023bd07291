"""Gymnasium conventions of the -v0 ids: episode limits, seeding, task arguments, ManiSkill wrappers,
vector envs, the determinism check on the wrapped env, and Stable-Baselines3's env checker."""

from __future__ import annotations

import subprocess
import sys
import textwrap
import warnings
from pathlib import Path

import gymnasium as gym
import numpy as np
import pytest

import capt_env
from capt_common.typed_yaml import ConfigError
from capt_env.registration import CATEGORY_ENV_NAMES, MAX_EPISODE_STEPS, env_id

ZERO = np.zeros(7, np.float32)


def _steps_until_done(env: gym.Env) -> int:
    env.reset(seed=0)
    for n in range(1, 10_000):
        _, _, terminated, truncated, _ = env.step(ZERO)
        if terminated or truncated:
            assert truncated and not terminated
            return n
    raise AssertionError("never truncated")


def test_v0_ids_register_and_honour_the_episode_limit() -> None:
    for category in CATEGORY_ENV_NAMES:
        assert gym.spec(env_id(category)).max_episode_steps == MAX_EPISODE_STEPS == 200
    assert gym.spec(capt_env.registration.GENERIC_ID).max_episode_steps == 200
    env = gym.make("CaptOpenLaptop-v0", obs_mode="state")
    longer = gym.make("CaptOpenLaptop-v0", obs_mode="state", max_episode_steps=230)
    shorter = gym.make("CaptOpenLaptop-v0", obs_mode="state", max_episode_steps=20)
    try:
        assert _steps_until_done(env) == 200
        assert _steps_until_done(longer) == 230  # ManiSkill's inner 200 no longer cuts it short
        assert _steps_until_done(shorter) == 20
    finally:
        env.close()
        longer.close()
        shorter.close()


def test_unseeded_resets_draw_fresh_entropy_and_seeded_ones_repeat() -> None:
    a = gym.make("CaptOpenLaptop-v0", obs_mode="state")
    b = gym.make("CaptOpenLaptop-v0", obs_mode="state")
    try:
        obs_a, _ = a.reset()
        obs_b, _ = b.reset()
        assert not np.allclose(obs_a, obs_b)  # two fresh processes' workers would differ too
        obs_a, _ = a.reset(seed=5)
        obs_b, _ = b.reset(seed=5)
        assert np.allclose(obs_a, obs_b)
    finally:
        a.close()
        b.close()


def test_task_argument_conflicts_and_yaml_paths(tmp_path: Path) -> None:
    with pytest.raises(ValueError, match="category='oven' conflicts with this env id's category='laptop'"):
        gym.make("CaptOpenLaptop-v0", task={"category": "oven"})
    task = tmp_path / "oven_task.yaml"
    task.write_text("category: oven\nyaw_noise: 0.1\n")
    env = gym.make("CaptOpenArticulated-v0", task=str(task), obs_mode="state")
    try:
        assert env.unwrapped.task_config.category == "oven" and env.unwrapped.task_config.yaw_noise == 0.1
    finally:
        env.close()
    task.write_text("category: oven\nyaw_noise: -1\n")
    with pytest.raises(ConfigError, match=r"oven_task\.yaml: yaw_noise must be >= 0, got -1"):
        gym.make("CaptOpenArticulated-v0", task=task, obs_mode="state")


def test_maniskill_wrappers_apply_before_unbatching() -> None:
    from mani_skill.utils.wrappers import FlattenRGBDObservationWrapper

    env = gym.make("CaptOpenLaptop-v0", obs_mode="rgbd", wrappers=[FlattenRGBDObservationWrapper])
    try:
        obs, _ = env.reset(seed=0)
        assert set(obs) == {"state", "rgb", "depth"} and obs["rgb"].ndim == 3  # no batch dimension
    finally:
        env.close()


def test_unknown_category_lists_only_real_categories() -> None:
    with pytest.raises(ValueError) as err:
        env_id("scissors")
    assert "scissors" not in str(err.value).split("known:")[1]


def test_async_vector_env_with_fork_fails_fast_and_says_to_use_spawn() -> None:
    script = textwrap.dedent("""
        import gymnasium as gym
        try:
            gym.make_vec("capt_env:CaptOpenLaptop-v0", 2, vectorization_mode="async", obs_mode="state")
        except Exception:
            pass
    """)
    result = subprocess.run([sys.executable, "-c", script], capture_output=True, text=True, timeout=240)
    assert "spawn" in result.stderr and "vector_kwargs={'context': 'spawn'}" in result.stderr


SINGLE_IDS = [env_id(category) for category in CATEGORY_ENV_NAMES] + [capt_env.registration.GENERIC_ID]


def _sb3_check(env: gym.Env) -> None:
    """SB3's checker with its extra warnings on; any warning it raises (not the libraries' deprecation
    notices) fails the test."""
    from stable_baselines3.common.env_checker import check_env

    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        check_env(env, warn=True, skip_render_check=True)
    assert [str(w.message) for w in caught if issubclass(w.category, UserWarning)] == []


@pytest.mark.parametrize("env_name", SINGLE_IDS)
def test_sb3_env_checker_on_every_single_env_id(env_name: str) -> None:
    """Every standard (-v0) id passes SB3's checker in state mode. The -ms-v0 ids are ManiSkill's own
    batched envs (torch tensors with a batch dimension), which SB3 reaches through the -v0 ids or
    ManiSkill's ``ManiSkillSB3VectorEnv``, not as a single ``gym.Env``."""
    task = {"category": "laptop"} if env_name == capt_env.registration.GENERIC_ID else None
    env = gym.make(env_name, obs_mode="state", task=task)
    try:
        _sb3_check(env)
    finally:
        env.close()


@pytest.mark.parametrize("obs_format", ["flat", "dict"])
def test_sb3_env_checker_on_the_wrapped_env(obs_format: str) -> None:
    env = capt_env.make_env("drawer_cabinet", {"source": "noisy_oracle", "obs_format": obs_format})
    try:
        _sb3_check(env)
    finally:
        env.close()
