"""``make_env``: a registered capt_env env wrapped in :class:`~capt_env.wrappers.CaptObservationWrapper`,
the env the policies (scripted opener, PPO) act in; also ``from capt_env import make_env``."""

from __future__ import annotations

from typing import Any

import gymnasium as gym

from capt_env.registration import GENERIC_ID, env_id
from capt_env.wrappers.config import PerceptionWrapperConfig
from capt_env.wrappers.perception_wrapper import CaptObservationWrapper


def make_env(category: str | None, wrapper: PerceptionWrapperConfig | dict | None = None,
             task: dict | None = None, obs_mode: str = "state", **kwargs: Any) -> CaptObservationWrapper:
    """A ``pd_ee_delta_pose`` env with joint-axis observations from ``wrapper`` (a
    :class:`PerceptionWrapperConfig` or its dict; default: the oracle source): of ``category`` (test
    split unless ``task`` says otherwise), or, with ``category`` None, of the user file
    ``task["object"]``. ``kwargs`` go to ``gym.make`` (e.g. ``render_mode``, ``max_episode_steps``)."""
    kwargs.setdefault("control_mode", "pd_ee_delta_pose")
    if category is None:
        if not (task or {}).get("object"):
            raise ValueError("make_env needs a category or a task with an 'object' file")
        env = gym.make(GENERIC_ID, obs_mode=obs_mode, task=dict(task), **kwargs)
        return CaptObservationWrapper(env, wrapper)
    task_cfg = {"split": "test", **(task or {})}
    env = gym.make(env_id(category), obs_mode=obs_mode, task=task_cfg, **kwargs)
    return CaptObservationWrapper(env, wrapper)
