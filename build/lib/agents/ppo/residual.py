"""Residual PPO: the policy corrects the scripted opener's action instead of acting from scratch.

The executed action is ``clip(base + scale * clip(residual, -1, 1), -1, 1)`` where ``base`` is
:class:`agents.scripted.ScriptedOpener`'s action (7,) for the same joint-axis observation and
``residual`` is the PPO action. The policy sees the wrapper's flat observation extended by the base
action and the opener's phase, so it can learn phase-dependent corrections (a firmer approach, a
pull that follows the drawer better) while an untrained policy (mean ~ 0, SB3 initialises its
action layer with gain 0.01) already behaves like the scripted opener. This is residual policy
learning (Silver et al. 2018, Johannink et al. 2019); both the base and the correction act only on
the joint-axis estimate, never on simulator state.

Layout of the extended observation (``float32``)::

    0:38    the flat joint-axis observation (capt_env.wrappers.joint_observation)
    38:45   the scripted opener's action for it (in [-1, 1])
    45:52   one-hot of the opener's phase (agents.scripted.opener.Phase order)

:class:`ResidualComposer` does the bookkeeping; :class:`ScriptedResidualWrapper` puts it around a
training env, and :class:`agents.ppo.policy.PPOPolicy` uses the same composer at evaluation.
"""

from __future__ import annotations

from typing import Any

import gymnasium as gym
import numpy as np
from gymnasium import spaces

from agents.scripted.config import ScriptedOpenerConfig
from agents.scripted.opener import Phase, ScriptedOpener
from capt_env.wrappers.joint_observation import OBSERVATION_SIZE, flat_space

ACTION_SIZE = 7
PHASES: tuple[Phase, ...] = tuple(Phase)
RESIDUAL_OBSERVATION_SIZE = OBSERVATION_SIZE + ACTION_SIZE + len(PHASES)


def residual_observation_space() -> spaces.Box:
    """Box of the extended observation (the flat observation's bounds, then [-1, 1] and [0, 1])."""
    base = flat_space()
    low = np.concatenate([base.low, -np.ones(ACTION_SIZE, np.float32), np.zeros(len(PHASES), np.float32)])
    high = np.concatenate([base.high, np.ones(ACTION_SIZE + len(PHASES), np.float32)])
    return spaces.Box(low.astype(np.float32), high.astype(np.float32), dtype=np.float32)


class ResidualComposer:
    """Runs the scripted opener beside a residual policy, one :meth:`observe` per env step.

    :param scale: how far a unit residual moves the action (in action units; 0.2 = 2 cm and 0.02
        rad per step under ``pd_ee_delta_pose``).
    :param opener_config: the scripted opener's config (its defaults when None).
    """

    def __init__(self, scale: float, opener_config: ScriptedOpenerConfig | None = None) -> None:
        if not 0.0 < scale <= 2.0:
            raise ValueError(f"residual scale must be in (0, 2], got {scale}")
        self.scale = float(scale)
        self.opener = ScriptedOpener(opener_config)
        self.base = np.zeros(ACTION_SIZE, np.float32)

    def reset(self) -> None:
        """Start a new episode (the opener back to its first phase)."""
        self.opener.reset()
        self.base = np.zeros(ACTION_SIZE, np.float32)

    def observe(self, obs: np.ndarray, info: dict[str, Any] | None = None) -> np.ndarray:
        """The extended observation (52,) for a flat observation (38,); steps the opener once and
        keeps its action as the base of the next :meth:`compose`."""
        flat = np.asarray(obs, dtype=np.float32)
        if flat.shape != (OBSERVATION_SIZE,):
            raise ValueError(f"residual PPO needs the flat ({OBSERVATION_SIZE},) observation, got shape "
                             f"{flat.shape}")
        self.base = np.asarray(self.opener.act(flat, info), dtype=np.float32)
        phase = np.zeros(len(PHASES), np.float32)
        phase[PHASES.index(self.opener.phase)] = 1.0
        return np.concatenate([flat, self.base, phase]).astype(np.float32)

    def compose(self, residual: np.ndarray) -> np.ndarray:
        """The executed action (7,): the last base action plus the scaled, clipped residual."""
        r = np.clip(np.asarray(residual, dtype=np.float32).reshape(ACTION_SIZE), -1.0, 1.0)
        return np.clip(self.base + self.scale * r, -1.0, 1.0).astype(np.float32)


class ScriptedResidualWrapper(gym.Wrapper, gym.utils.RecordConstructorArgs):
    """A flat joint-axis env whose actions are residuals on the scripted opener (module docstring).

    Wraps :class:`capt_env.wrappers.CaptObservationWrapper` with ``obs_format: flat``; the
    observation space becomes :func:`residual_observation_space`, the action space stays the Box (7,).
    ``info["base_action"]`` is the opener's action that the step's residual was added to.
    """

    def __init__(self, env: gym.Env, scale: float, opener_config: ScriptedOpenerConfig | None = None) -> None:
        gym.utils.RecordConstructorArgs.__init__(self, scale=scale, opener_config=opener_config)
        gym.Wrapper.__init__(self, env)
        if env.observation_space.shape != (OBSERVATION_SIZE,):
            raise ValueError(f"ScriptedResidualWrapper needs the flat ({OBSERVATION_SIZE},) joint-axis "
                             f"observation, got space {env.observation_space}")
        self.composer = ResidualComposer(scale, opener_config)
        self.observation_space = residual_observation_space()

    def reset(self, *, seed: int | None = None, options: dict | None = None) -> tuple[np.ndarray, dict]:
        obs, info = self.env.reset(seed=seed, options=options)
        self.composer.reset()
        return self.composer.observe(obs, info), info

    def step(self, action: Any) -> tuple[np.ndarray, float, bool, bool, dict]:
        executed = self.composer.compose(action)
        base = self.composer.base.copy()
        obs, reward, terminated, truncated, info = self.env.step(executed)
        info = {**info, "base_action": base}
        return self.composer.observe(obs, info), reward, terminated, truncated, info
