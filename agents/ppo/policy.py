"""A trained PPO model as a policy with the scripted opener's interface (``reset``, ``act``).

A residual model (``residual.enabled`` in its run's ``config.yaml``) is run with the scripted
opener beside it, exactly as in training (agents.ppo.residual).
"""

from __future__ import annotations

import contextlib
import pickle
import warnings
from collections.abc import Iterator
from pathlib import Path
from typing import Any

import numpy as np
import yaml
from stable_baselines3 import PPO
from stable_baselines3.common.running_mean_std import RunningMeanStd
from stable_baselines3.common.vec_env import VecNormalize

from agents.ppo.residual import RESIDUAL_OBSERVATION_SIZE, ResidualComposer
from agents.ppo.train import CONFIG_FILE, vecnormalize_path
from agents.scripted.config import ScriptedOpenerConfig
from capt_common.typed_yaml import from_dict

CONSTANT_FEATURE_VAR = 1e-6
"""Training variance under which an observation feature counts as constant (see :class:`PPOPolicy`):
the running statistics leave ~1e-9 (their prior, variance 1 at count 1e-4) on a feature that never
changed; the least-varying real feature of the shipped policies has ~4e-5."""


@contextlib.contextmanager
def _numpy1_pickles() -> Iterator[None]:
    """Unpickle files written under numpy 1 without numpy 2's warning that they name ``numpy.core``
    (the shipped policies are saved under numpy 1.26 so that numpy 1 and 2 both load them)."""
    with warnings.catch_warnings():
        warnings.filterwarnings("ignore", message=r"numpy\.core", category=DeprecationWarning)
        yield


def run_config_of(model_path: str | Path) -> dict[str, Any] | None:
    """The ``config.yaml`` of the run a model belongs to (beside ``final.zip``, or one level up from
    ``checkpoints/ppo_<N>_steps.zip``), as a dict; None when there is none."""
    model_path = Path(model_path)
    for folder in (model_path.parent, model_path.parent.parent):
        if (folder / CONFIG_FILE).is_file():
            loaded = yaml.safe_load((folder / CONFIG_FILE).read_text())
            return loaded if isinstance(loaded, dict) else None
    return None


class PPOPolicy:
    """Deterministic actions of a saved SB3 PPO model on flat joint-axis observations.

    :param model: the PPO model.
    :param obs_norm: its ``VecNormalize`` statistics (observations are normalised with them, in
        evaluation mode: the statistics stay fixed), or None when trained without normalisation.
    :param residual: for a residual model, the composer that runs the scripted opener beside it.

    Features that never varied in training (variance below ``CONSTANT_FEATURE_VAR`` in the
    normalisation statistics: the confidence under the oracle sources, which is always 1, and the
    joint type of a single-joint-type category) are pinned to their training value. VecNormalize
    would divide any change of them by ``sqrt(epsilon)`` and saturate its clip at +-10, an input the
    policy never saw: CAPT's confidence below 1 did exactly that to the laptop's residual policy.
    """

    def __init__(self, model: PPO, obs_norm: VecNormalize | None = None,
                 residual: ResidualComposer | None = None) -> None:
        expected = (RESIDUAL_OBSERVATION_SIZE,) if residual is not None else None
        if expected is not None and model.observation_space.shape != expected:
            raise ValueError(f"a residual PPO model takes observations of shape {expected}, this one "
                             f"{model.observation_space.shape}")
        self.model = model
        self.obs_norm = obs_norm
        self.residual = residual
        self._pinned = np.zeros(0, dtype=np.int64)  # indices of features fixed at training values
        self._pinned_values = np.zeros(0, dtype=np.float32)
        if obs_norm is not None:
            obs_norm.training = False
            rms = obs_norm.obs_rms
            if not isinstance(rms, RunningMeanStd):
                raise ValueError("PPOPolicy takes flat (Box) observations; these statistics are "
                                 f"{type(rms).__name__}")
            constant = np.asarray(rms.var) < CONSTANT_FEATURE_VAR
            self._pinned = np.flatnonzero(constant)
            self._pinned_values = np.asarray(rms.mean, dtype=np.float32)[constant]

    @classmethod
    def load(cls, path: str | Path, vecnormalize: str | Path | None = None,
             device: str = "cpu") -> PPOPolicy:
        """Load ``path`` (``final.zip`` or a ``ppo_<N>_steps.zip`` checkpoint) and, when it exists, the
        normalisation saved beside it (``vecnormalize.pkl`` / ``ppo_vecnormalize_<N>_steps.pkl``) or
        given as ``vecnormalize``. Both files are unpickled: load only files you trust. The run's
        ``config.yaml`` (see :func:`run_config_of`) says whether the model is residual."""
        path = Path(path)
        if not path.is_file():
            raise FileNotFoundError(f"no PPO model at {path}")
        norm_path = Path(vecnormalize) if vecnormalize is not None else vecnormalize_path(path)
        obs_norm = None
        if norm_path.is_file():
            with norm_path.open("rb") as fh, _numpy1_pickles():
                obs_norm = pickle.load(fh)  # noqa: S301 - SB3's own format; trusted files only
            if not isinstance(obs_norm, VecNormalize):
                raise ValueError(f"{norm_path} holds a {type(obs_norm).__name__}, "
                                 "not VecNormalize statistics")
        elif vecnormalize is not None:
            raise FileNotFoundError(f"no VecNormalize statistics at {norm_path}")
        with _numpy1_pickles():
            model = PPO.load(path, device=device)
        residual = None
        run_config = run_config_of(path) or {}
        residual_cfg = run_config.get("residual") or {}
        if residual_cfg.get("enabled", False):
            opener = from_dict(ScriptedOpenerConfig, residual_cfg.get("opener") or {},
                               where=f"{path} run config residual.opener")
            residual = ResidualComposer(float(residual_cfg.get("scale", 0.2)), opener)
        elif model.observation_space.shape == (RESIDUAL_OBSERVATION_SIZE,):
            raise ValueError(f"{path} is a residual PPO model but no run config.yaml with "
                             "'residual: {enabled: true, scale: ...}' lies beside it")
        return cls(model, obs_norm, residual)

    def reset(self) -> None:
        """Start a new episode (the MLP keeps no state; a residual model's scripted opener restarts)."""
        if self.residual is not None:
            self.residual.reset()

    def act(self, obs: np.ndarray, info: dict[str, Any] | None = None) -> np.ndarray:
        """Action (7,) float32 in [-1, 1] for ``pd_ee_delta_pose`` from a flat (38,) observation.

        The mean of the Gaussian policy (deterministic), clipped to the action bounds; ``info`` is
        unused (same signature as :meth:`agents.scripted.ScriptedOpener.act`).
        """
        x = np.asarray(obs, dtype=np.float32)
        if self.residual is not None:
            x = self.residual.observe(x, info)
        if self.obs_norm is not None:
            if self._pinned.size:
                x = x.copy()
                x[..., self._pinned] = self._pinned_values
            x = self.obs_norm.normalize_obs(x).astype(np.float32)
        action, _ = self.model.predict(x, deterministic=True)
        action = np.asarray(action, dtype=np.float32)
        return self.residual.compose(action) if self.residual is not None else action
