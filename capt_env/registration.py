"""Environment ids: ManiSkill-native batched ids and standard single-env Gymnasium ids.

Two ids per object category ``Cat`` (Laptop, Oven, WashingMachine, Eyeglasses, DrawerCabinet,
CabinetDoor, Scissors) plus a generic one taking ``category=`` or ``object=``:

- ``CaptOpen<Cat>-v0`` / ``CaptOpenArticulated-v0``: a standard Gymnasium env (numpy arrays, no
  batch dimension, CPU simulation), what SB3 and ``gymnasium.utils.env_checker`` expect.
- ``CaptOpen<Cat>-ms-v0`` / ``CaptOpenArticulated-ms-v0``: the ManiSkill env itself (batched torch
  tensors; ``num_envs > 1`` and ``sim_backend="physx_cuda"`` on a GPU).

``import capt_env`` registers them; ``gymnasium.make("capt_env:CaptOpenLaptop-v0")`` imports the
package itself, so other projects need no import of their own.
"""

from __future__ import annotations

from typing import Any

import gymnasium as gym
import numpy as np

MAX_EPISODE_STEPS = 200

CATEGORY_ENV_NAMES = {
    "laptop": "Laptop",
    "oven": "Oven",
    "washing_machine": "WashingMachine",
    "eyeglasses": "Eyeglasses",
    "drawer_cabinet": "DrawerCabinet",
    "cabinet_door": "CabinetDoor",
    "scissors": "Scissors",
}
GENERIC_ID = "CaptOpenArticulated-v0"
GENERIC_MS_ID = "CaptOpenArticulated-ms-v0"

_registered = False


def env_id(category: str, maniskill: bool = False) -> str:
    """The env id of a category, e.g. ``env_id("drawer_cabinet") == "CaptOpenDrawerCabinet-v0"``."""
    if category not in CATEGORY_ENV_NAMES:
        raise ValueError(f"unknown category {category!r}; known: {sorted(CATEGORY_ENV_NAMES)}")
    return f"CaptOpen{CATEGORY_ENV_NAMES[category]}-{'ms-' if maniskill else ''}v0"


class OwnedArrays(gym.Wrapper):
    """Copy observations and infos so each call returns arrays the caller owns.

    ManiSkill's numpy views share memory with simulator buffers that the next step overwrites;
    Gymnasium requires fresh data per call (and users keep what they are given).
    """

    def reset(self, **kwargs: Any) -> tuple[Any, dict]:
        obs, info = self.env.reset(**kwargs)
        return _copy_tree(obs), _copy_tree(info)

    def step(self, action: Any) -> tuple[Any, Any, Any, Any, dict]:
        obs, reward, terminated, truncated, info = self.env.step(action)
        return _copy_tree(obs), float(reward), bool(terminated), bool(truncated), _copy_tree(info)


def _copy_tree(x: Any) -> Any:
    if isinstance(x, dict):
        return {k: _copy_tree(v) for k, v in x.items()}
    if isinstance(x, np.ndarray):
        return x.copy()
    return x


def make_single_env(maniskill_id: str, **kwargs: Any) -> gym.Env:
    """Create a ManiSkill id with one CPU env and unbatch it to plain numpy (``CPUGymWrapper``)."""
    from mani_skill.utils.wrappers.gymnasium import CPUGymWrapper

    if kwargs.get("num_envs", 1) != 1:
        raise ValueError("the single-env ids take num_envs=1; use the '-ms-' ids for batched envs")
    kwargs.pop("num_envs", None)
    env = gym.make(maniskill_id, num_envs=1, **kwargs)
    return OwnedArrays(CPUGymWrapper(env))


def register_envs() -> None:
    """Register every id with ManiSkill and Gymnasium (idempotent)."""
    global _registered
    if _registered:
        return
    from mani_skill.utils.registration import register_env

    from capt_env.objects.registry import CATEGORIES
    from capt_env.tasks.open_articulated import OpenArticulatedEnv

    register_env(GENERIC_MS_ID, max_episode_steps=MAX_EPISODE_STEPS)(OpenArticulatedEnv)
    gym.register(GENERIC_ID, entry_point=make_single_env, kwargs={"maniskill_id": GENERIC_MS_ID},
                 disable_env_checker=True)
    for category in CATEGORIES:
        ms_id = env_id(category, maniskill=True)
        register_env(ms_id, max_episode_steps=MAX_EPISODE_STEPS, category=category)(OpenArticulatedEnv)
        gym.register(env_id(category), entry_point=make_single_env, kwargs={"maniskill_id": ms_id},
                     disable_env_checker=True)
    _registered = True
