"""Train SB3 PPO on joint-axis observations: vector envs, the model, checkpoints, resume, a summary.

Reads top to bottom: :func:`make_vec_env` (train-split envs behind ``CaptObservationWrapper``,
``Monitor`` and optionally ``VecNormalize``), :func:`train_ppo` (fresh model or the latest
checkpoint, ``learn``, ``final.zip``), :func:`episode_stats` (the summary's numbers).

Layout of ``out_dir``::

    config.yaml                      the config of the run (a resume must match it)
    checkpoints/ppo_<N>_steps.zip    every checkpoint_every_steps env steps, and at the end
    checkpoints/ppo_vecnormalize_<N>_steps.pkl
    logs/from_<N>/progress.csv       SB3's log of the run that started at step N (TensorBoard
                                     events too, when tensorboard is installed)
    final.zip, vecnormalize.pkl      the last model and its observation normalisation

With ``vec_env: processes`` the envs are CPU envs, one process each (:func:`make_vec_env`). With
``vec_env: maniskill`` they are the sub-scenes of one batched ManiSkill env, on ManiSkill's GPU
simulation when ``n_envs > 1`` (:func:`make_maniskill_vec_env`; ground-truth sources only). That
path is tested on the CPU with one sub-scene; it has not run on a GPU here.
"""

from __future__ import annotations

import re
import shutil
import time
from collections.abc import Callable
from dataclasses import replace
from functools import partial
from pathlib import Path
from typing import Any

import gymnasium as gym
import numpy as np
import yaml
from stable_baselines3 import PPO
from stable_baselines3.common.callbacks import BaseCallback, CallbackList, CheckpointCallback
from stable_baselines3.common.logger import configure
from stable_baselines3.common.monitor import Monitor
from stable_baselines3.common.utils import set_random_seed
from stable_baselines3.common.vec_env import DummyVecEnv, SubprocVecEnv, VecEnv, VecNormalize

from agents.ppo.config import PPOTrainConfig
from capt_common.typed_yaml import ConfigError, from_dict, to_dict

CHECKPOINT_PREFIX = "ppo"
FINAL_MODEL = "final.zip"
FINAL_VECNORMALIZE = "vecnormalize.pkl"
CONFIG_FILE = "config.yaml"
# config keys a resumed run may change; any other difference is an error
RESUMABLE_CHANGES = frozenset({"total_timesteps", "device", "checkpoint_every_steps", "n_envs"})
_CHECKPOINT_RE = re.compile(rf"^{CHECKPOINT_PREFIX}_(\d+)_steps\.zip$")


class ContinueAfterSuccess(gym.Wrapper):
    """Training episodes that run to their step limit instead of ending at the task's success.

    ManiSkill ends an episode (``terminated``) the first step the part is open and at rest. With a
    per-step dense reward that ending is a loss for the agent: holding the part open but moving
    earns ~3 per step for the rest of the episode, succeeding earns 5 once. Without the
    termination the best return is to open the part soon and leave it open and at rest (5 per
    step), and ``success`` at the last step (what ``Monitor`` records) means it stayed open.
    """

    def step(self, action: Any) -> tuple[Any, float, bool, bool, dict]:
        obs, reward, terminated, truncated, info = self.env.step(action)
        if terminated and bool(info.get("success", False)):
            terminated = False
        return obs, reward, terminated, truncated, info


class SuccessRateLogger(BaseCallback):
    """Logs ``rollout/success_rate``: the task's success at the last step of SB3's window of recent
    episodes (the ``success`` that ``Monitor`` records)."""

    def _on_step(self) -> bool:
        return True

    def _on_rollout_end(self) -> None:
        rate = episode_stats(self.model)["success_rate"]
        if rate is not None:
            self.logger.record("rollout/success_rate", rate)


def make_train_env(config: PPOTrainConfig, rank: int) -> gym.Env:
    """Env number ``rank`` of a training run: train split, wrapped, with ``Monitor`` (records
    episode return, length and the task's ``success`` at the episode's last step)."""
    import capt_env  # noqa: F401 - registers the ids in a fresh worker process
    from capt_env.env_factory import make_env

    perception = replace(config.perception, seed=config.perception.seed + rank)
    env: gym.Env = make_env(config.category, perception, task=config.train_task(),
                            obs_mode=config.obs_mode, max_episode_steps=config.max_episode_steps)
    if config.residual.enabled:
        from agents.ppo.residual import ScriptedResidualWrapper

        env = ScriptedResidualWrapper(env, config.residual.scale, config.residual.opener)
    if config.continue_after_success:
        env = ContinueAfterSuccess(env)
    return Monitor(env, info_keywords=("success",))


def make_maniskill_vec_env(config: PPOTrainConfig) -> VecEnv:
    """``n_envs`` sub-scenes of one batched ManiSkill env of the train split behind
    ``BatchedOracleObservation`` and ``ManiSkillVecEnv`` (``vec_env: maniskill``); not yet
    normalised or seeded. Raises ConfigError when the simulation backend needs CUDA and none is here."""
    import torch

    import capt_env  # noqa: F401 - registers the ids
    from agents.ppo.maniskill_vec_env import ManiSkillVecEnv
    from capt_env.registration import env_id
    from capt_env.wrappers.batched_oracle_observation import BatchedOracleObservation

    backend = config.resolved_sim_backend()
    if backend == "physx_cuda" and not torch.cuda.is_available():
        raise ConfigError(f"vec_env 'maniskill' with {config.n_envs} envs needs ManiSkill's GPU simulation "
                          f"(sim_backend physx_cuda) and this machine has no CUDA device: use n_envs: 1, "
                          f"or vec_env: processes")
    env = gym.make(env_id(config.category, maniskill=True), num_envs=config.n_envs, obs_mode=config.obs_mode,
                   sim_backend=backend, task=config.train_task(), max_episode_steps=config.max_episode_steps)
    return ManiSkillVecEnv(BatchedOracleObservation(env, config.perception), config.continue_after_success,
                           config.reconfigure_every_steps)


def make_vec_env(config: PPOTrainConfig) -> VecEnv:
    """``n_envs`` training envs: ``SubprocVecEnv`` (one process each) when > 1, else ``DummyVecEnv``,
    or the batched ManiSkill env with ``vec_env: maniskill``; not yet normalised or seeded (PPO seeds
    them with ``seed + rank``)."""
    if config.vec_env == "maniskill":
        return make_maniskill_vec_env(config)
    fns = [partial(make_train_env, config, rank) for rank in range(config.n_envs)]
    return SubprocVecEnv(fns) if config.n_envs > 1 else DummyVecEnv(fns)


def latest_checkpoint(out_dir: str | Path) -> tuple[Path, int] | None:
    """The checkpoint of ``out_dir`` with the most env steps, and that step count; None if none."""
    found = [(int(m.group(1)), p) for p in (Path(out_dir) / "checkpoints").glob("*.zip")
             if (m := _CHECKPOINT_RE.match(p.name))]
    if not found:
        return None
    steps, path = max(found)
    return path, steps


def vecnormalize_path(model_path: str | Path) -> Path:
    """Where the observation normalisation of a saved model lies (it may not exist).

    ``final.zip`` -> ``vecnormalize.pkl``; ``ppo_<N>_steps.zip`` -> ``ppo_vecnormalize_<N>_steps.pkl``.
    """
    model_path = Path(model_path)
    m = _CHECKPOINT_RE.match(model_path.name)
    if m:
        return model_path.with_name(f"{CHECKPOINT_PREFIX}_vecnormalize_{m.group(1)}_steps.pkl")
    return model_path.with_name(FINAL_VECNORMALIZE)


def episode_stats(model: PPO) -> dict[str, float | int | None]:
    """Mean return, length (steps) and success rate over SB3's window of the last <= 100 episodes."""
    infos = list(model.ep_info_buffer or [])
    if not infos:
        return {"episodes_in_stats": 0, "mean_episode_reward": None, "mean_episode_length": None,
                "success_rate": None}
    successes = [float(i["success"]) for i in infos if "success" in i]
    return {"episodes_in_stats": len(infos),
            "mean_episode_reward": float(np.mean([i["r"] for i in infos])),
            "mean_episode_length": float(np.mean([i["l"] for i in infos])),
            "success_rate": float(np.mean(successes)) if successes else None}


def _check_resumable(saved: dict[str, Any], config: PPOTrainConfig, out_dir: Path) -> None:
    """Raise ConfigError if ``config`` changes more of the saved run's config than a resume may.
    The saved config is read with today's defaults (a field added since it was saved is not a
    change); a key that no longer exists is an error that names it."""
    saved = to_dict(from_dict(PPOTrainConfig, saved, where=str(out_dir / CONFIG_FILE)))
    current = to_dict(config)
    changed = sorted(k for k in set(saved) | set(current)
                     if k not in RESUMABLE_CHANGES and saved.get(k) != current.get(k))
    if changed:
        raise ConfigError(f"{out_dir / CONFIG_FILE}: resuming with changed {changed}; only "
                          f"{sorted(RESUMABLE_CHANGES)} may change (use another out dir or resume=False)")


def _logger_formats(log_to_stdout: bool) -> list[str]:
    formats = ["csv"]
    try:
        import tensorboard  # noqa: F401
    except ImportError:
        pass
    else:
        formats.append("tensorboard")
    return formats + (["stdout"] if log_to_stdout else [])


def train_ppo(config: PPOTrainConfig, out_dir: str | Path, resume: bool = True,
              log_to_stdout: bool = False,
              on_trained: Callable[[PPO, VecEnv], None] | None = None) -> dict[str, Any]:
    """Train (or continue training) PPO until ``config.total_timesteps`` env steps; return a summary.

    With ``resume`` and a checkpoint in ``out_dir/checkpoints``, the latest one (and its
    ``VecNormalize`` statistics) is loaded and training continues with ``reset_num_timesteps=False``
    for the steps still missing; a run already at its total only re-saves ``final.zip``. Without
    ``resume``, earlier checkpoints in ``out_dir`` are ignored (and later ones may overwrite them).
    Seeded by ``config.seed`` (a resumed run reseeds with ``seed + steps done``).

    :param config: the run's config (validated).
    :param out_dir: run directory (created); layout in the module docstring.
    :param resume: continue from the latest checkpoint when there is one.
    :param log_to_stdout: also print SB3's table after each rollout.
    :param on_trained: called with the trained model and its (normalising) vec env before they close.
    :returns: ``num_timesteps`` (env steps done in all), ``start_timesteps``, ``steps_this_run``,
        ``wall_time_s`` and ``steps_per_s`` of this run, ``resumed_from`` (checkpoint path or None),
        paths of ``final_model``, ``vecnormalize`` (None without normalisation) and ``log_dir``,
        ``logger_formats``, and :func:`episode_stats` of the last episodes.
    """
    config.validate()
    out_dir = Path(out_dir)
    out_dir.mkdir(parents=True, exist_ok=True)
    ckpt_dir = out_dir / "checkpoints"
    found = latest_checkpoint(out_dir) if resume else None
    if found is not None and (out_dir / CONFIG_FILE).is_file():
        _check_resumable(yaml.safe_load((out_dir / CONFIG_FILE).read_text()), config, out_dir)
    (out_dir / CONFIG_FILE).write_text(yaml.safe_dump(to_dict(config), sort_keys=False))

    set_random_seed(config.seed)
    venv: VecEnv = make_vec_env(config)
    try:
        if found is not None:
            path, _ = found
            if config.normalize_obs:
                venv = VecNormalize.load(str(vecnormalize_path(path)), venv)
                venv.training = True
            model = PPO.load(path, env=venv, device=config.device)
            model.set_random_seed(config.seed + model.num_timesteps)
        else:
            if config.normalize_obs:
                venv = VecNormalize(venv, norm_obs=True, norm_reward=False, gamma=config.ppo.gamma)
            hp = config.ppo
            model = PPO("MlpPolicy", venv, n_steps=hp.n_steps, batch_size=hp.batch_size,
                        n_epochs=hp.n_epochs, learning_rate=hp.learning_rate, gamma=hp.gamma,
                        gae_lambda=hp.gae_lambda, clip_range=hp.clip_range, ent_coef=hp.ent_coef,
                        vf_coef=hp.vf_coef, max_grad_norm=hp.max_grad_norm,
                        policy_kwargs={"net_arch": {"pi": list(hp.net_arch), "vf": list(hp.net_arch)},
                                       "log_std_init": hp.log_std_init},
                        seed=config.seed, device=config.device, verbose=0)
        start = int(model.num_timesteps)
        log_dir = out_dir / "logs" / f"from_{start}"
        formats = _logger_formats(log_to_stdout)
        model.set_logger(configure(str(log_dir), formats))

        remaining = config.total_timesteps - start
        t0 = time.perf_counter()
        if remaining > 0:
            checkpoints = CheckpointCallback(
                save_freq=max(1, config.checkpoint_every_steps // config.n_envs),
                save_path=str(ckpt_dir), name_prefix=CHECKPOINT_PREFIX,
                save_vecnormalize=config.normalize_obs)
            model.learn(total_timesteps=remaining, callback=CallbackList([checkpoints, SuccessRateLogger()]),
                        reset_num_timesteps=found is None, progress_bar=False)
        wall = time.perf_counter() - t0

        steps = int(model.num_timesteps)
        model.save(out_dir / FINAL_MODEL)
        ckpt_dir.mkdir(exist_ok=True)
        shutil.copyfile(out_dir / FINAL_MODEL, ckpt_dir / f"{CHECKPOINT_PREFIX}_{steps}_steps.zip")
        vecnorm = None
        if isinstance(venv, VecNormalize):
            vecnorm = out_dir / FINAL_VECNORMALIZE
            venv.save(str(vecnorm))
            shutil.copyfile(vecnorm, vecnormalize_path(ckpt_dir / f"{CHECKPOINT_PREFIX}_{steps}_steps.zip"))
        if on_trained is not None:
            on_trained(model, venv)
        return {"category": config.category, "perception": config.perception.source,
                "n_envs": config.n_envs, "total_timesteps": config.total_timesteps,
                "num_timesteps": steps, "start_timesteps": start, "steps_this_run": steps - start,
                "wall_time_s": wall, "steps_per_s": (steps - start) / wall if wall > 0 else None,
                "resumed_from": str(found[0]) if found is not None else None,
                "final_model": str(out_dir / FINAL_MODEL),
                "vecnormalize": str(vecnorm) if vecnorm is not None else None,
                "log_dir": str(log_dir), "logger_formats": formats, **episode_stats(model)}
    finally:
        venv.close()
