"""Environment ids: ManiSkill-native batched ids and standard single-env Gymnasium ids.

Two ids per object category ``Cat`` (Laptop, Oven, WashingMachine, Eyeglasses, DrawerCabinet,
CabinetDoor) plus a generic one taking ``task={"category": ...}`` or ``task={"object": PATH}``:

- ``CaptOpen<Cat>-v0`` / ``CaptOpenArticulated-v0``: a standard Gymnasium env (numpy arrays, no
  batch dimension, CPU simulation), what SB3 and ``gymnasium.utils.env_checker`` expect. Episodes
  are truncated after ``MAX_EPISODE_STEPS`` (the spec's ``max_episode_steps``; ``gym.make(id,
  max_episode_steps=N)`` sets another limit). ``wrappers=[W, ...]`` applies ManiSkill or Gymnasium
  wrappers (classes or callables ``env -> env``) to the ManiSkill env before it is unbatched, e.g.
  ``mani_skill.utils.wrappers.FlattenRGBDObservationWrapper``.
- ``CaptOpen<Cat>-ms-v0`` / ``CaptOpenArticulated-ms-v0``: the ManiSkill env itself (batched torch
  tensors; ``num_envs > 1`` and ``sim_backend="physx_cuda"`` on a GPU, a different instance of the
  category in each sub-scene).

``gymnasium.make("capt_env:CaptOpenLaptop-v0")`` imports the package and registers the ids, so
other projects need no import of their own (Gymnasium 1.x reads no plugin entry points);
``import capt_env`` registers them too.
"""

from __future__ import annotations

import functools
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
    "sliding_panel": "SlidingPanel",
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


_UNLIMITED = 10**9  # the inner ManiSkill limit (int32-safe); Gymnasium's TimeLimit from the spec truncates


def make_single_env(maniskill_id: str, wrappers: list | tuple = (), **kwargs: Any) -> gym.Env:
    """Create a ManiSkill id with one CPU env, apply ``wrappers`` to it, and unbatch it to plain
    numpy (``CPUGymWrapper``). The episode limit is Gymnasium's (the registered 200 steps or the
    ``max_episode_steps`` given to ``gym.make``), so ManiSkill's own limit is lifted here."""
    from mani_skill.utils.wrappers.gymnasium import CPUGymWrapper

    if kwargs.get("num_envs", 1) != 1:
        raise ValueError("the single-env ids take num_envs=1; use the '-ms-' ids for batched envs")
    kwargs.pop("num_envs", None)
    _refuse_forked_child()
    env = gym.make(maniskill_id, num_envs=1, max_episode_steps=_UNLIMITED, **kwargs)
    for wrapper in wrappers:
        if not callable(wrapper):
            raise TypeError(f"wrappers must be wrapper classes or callables env -> env, got {wrapper!r}")
        env = wrapper(env)
    return OwnedArrays(CPUGymWrapper(env))


_SIMULATOR_PID: int | None = None


def _refuse_forked_child() -> None:
    """Fail fast in a process forked from one that already built a simulator: SAPIEN's threads and
    device handles do not survive ``fork`` and the child would hang (Gymnasium's async vector env
    forks by default on Linux after building one env in the parent)."""
    import os

    global _SIMULATOR_PID
    if _SIMULATOR_PID is not None and _SIMULATOR_PID != os.getpid():
        raise RuntimeError(
            "capt_env envs cannot be created in a forked process after the parent built one; use the "
            "spawn start method, e.g. gym.make_vec(id, n, vectorization_mode='async', "
            "vector_kwargs={'context': 'spawn'}) or SB3's SubprocVecEnv(..., start_method='spawn')")
    _SIMULATOR_PID = os.getpid()


def make_maniskill_env(uid: str, **kwargs: Any) -> gym.Env:
    """Entry point of the ``-ms-v0`` ids: the ManiSkill env ``uid`` (registered with ManiSkill on
    first use, so that importing capt_env does not import the simulator)."""
    from mani_skill.utils.registration import REGISTERED_ENVS, register

    from capt_env.tasks.open_articulated import OpenArticulatedEnv

    if uid not in REGISTERED_ENVS:
        register(uid, OpenArticulatedEnv, max_episode_steps=MAX_EPISODE_STEPS)
    return REGISTERED_ENVS[uid].make(**kwargs)


def _register_maniskill_id(uid: str, **kwargs: Any) -> None:
    """A Gymnasium registration like ManiSkill's ``register_env`` makes (its batched TimeLimit
    wrapper included), without importing ManiSkill now."""
    from gymnasium.envs.registration import WrapperSpec

    gym.register(
        uid, entry_point=functools.partial(make_maniskill_env, uid=uid), max_episode_steps=MAX_EPISODE_STEPS,
        disable_env_checker=True, kwargs=kwargs,
        additional_wrappers=(WrapperSpec("MSTimeLimit", "mani_skill.utils.registration:TimeLimitWrapper",
                                         {"max_episode_steps": MAX_EPISODE_STEPS}),),
    )


def register_envs() -> None:
    """Register every id with Gymnasium (idempotent; cheap: the simulator is imported on first use)."""
    global _registered
    if _registered:
        return
    from capt_env.objects.registry import CATEGORIES

    _register_maniskill_id(GENERIC_MS_ID)
    gym.register(GENERIC_ID, entry_point=make_single_env, kwargs={"maniskill_id": GENERIC_MS_ID},
                 max_episode_steps=MAX_EPISODE_STEPS, disable_env_checker=True)
    for category in CATEGORIES:
        ms_id = env_id(category, maniskill=True)
        _register_maniskill_id(ms_id, category=category)
        gym.register(env_id(category), entry_point=make_single_env, kwargs={"maniskill_id": ms_id},
                     max_episode_steps=MAX_EPISODE_STEPS, disable_env_checker=True)
    _registered = True
