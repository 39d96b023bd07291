"""A trained PPO model as a policy with the scripted opener's interface (``reset``, ``act``)."""

from __future__ import annotations

import pickle
from pathlib import Path
from typing import Any

import numpy as np
from stable_baselines3 import PPO
from stable_baselines3.common.vec_env import VecNormalize

from agents.ppo.train import vecnormalize_path


class PPOPolicy:
    """Deterministic actions of a saved SB3 PPO model on flat joint-axis observations.

    :param model: the PPO model.
    :param obs_norm: its ``VecNormalize`` statistics (observations are normalised with them, in
        evaluation mode: the statistics stay fixed), or None when trained without normalisation.
    """

    def __init__(self, model: PPO, obs_norm: VecNormalize | None = None) -> None:
        self.model = model
        self.obs_norm = obs_norm
        if obs_norm is not None:
            obs_norm.training = False

    @classmethod
    def load(cls, path: str | Path, vecnormalize: str | Path | None = None,
             device: str = "cpu") -> PPOPolicy:
        """Load ``path`` (``final.zip`` or a ``ppo_<N>_steps.zip`` checkpoint) and, when it exists, the
        normalisation saved beside it (``vecnormalize.pkl`` / ``ppo_vecnormalize_<N>_steps.pkl``) or
        given as ``vecnormalize``. Both files are unpickled: load only files you trust."""
        path = Path(path)
        if not path.is_file():
            raise FileNotFoundError(f"no PPO model at {path}")
        norm_path = Path(vecnormalize) if vecnormalize is not None else vecnormalize_path(path)
        obs_norm = None
        if norm_path.is_file():
            with norm_path.open("rb") as fh:
                obs_norm = pickle.load(fh)  # noqa: S301 - SB3's own format; trusted files only
            if not isinstance(obs_norm, VecNormalize):
                raise ValueError(f"{norm_path} holds a {type(obs_norm).__name__}, "
                                 "not VecNormalize statistics")
        elif vecnormalize is not None:
            raise FileNotFoundError(f"no VecNormalize statistics at {norm_path}")
        return cls(PPO.load(path, device=device), obs_norm)

    def reset(self) -> None:
        """Start a new episode (the MLP policy keeps no state)."""

    def act(self, obs: np.ndarray, info: dict[str, Any] | None = None) -> np.ndarray:
        """Action (7,) float32 in [-1, 1] for ``pd_ee_delta_pose`` from a flat (38,) observation.

        The mean of the Gaussian policy (deterministic), clipped to the action bounds; ``info`` is
        unused (same signature as :meth:`agents.scripted.ScriptedOpener.act`).
        """
        x = np.asarray(obs, dtype=np.float32)
        if self.obs_norm is not None:
            x = self.obs_norm.normalize_obs(x).astype(np.float32)
        action, _ = self.model.predict(x, deterministic=True)
        return np.asarray(action, dtype=np.float32)
