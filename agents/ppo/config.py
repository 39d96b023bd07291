"""Typed config of PPO training on joint-axis observations (YAML: ``configs/ppo/``)."""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import Any, Literal

from agents.scripted.config import ScriptedOpenerConfig
from capt_common.typed_yaml import from_dict, require
from capt_env.registration import CATEGORY_ENV_NAMES, MAX_EPISODE_STEPS
from capt_env.tasks.config import TaskConfig
from capt_env.wrappers.config import PerceptionWrapperConfig

ObsMode = Literal["state", "pointcloud"]
VecEnvKind = Literal["processes", "maniskill"]
SimBackend = Literal["auto", "physx_cpu", "physx_cuda"]


@dataclass(frozen=True)
class PPOHyperparams:
    """SB3 ``PPO`` hyperparameters (steps are env steps per env; rates per gradient step).

    ``n_steps`` env steps per env and rollout (a rollout holds ``n_steps * n_envs`` transitions),
    split into minibatches of ``batch_size`` for ``n_epochs`` passes. ``learning_rate`` (Adam),
    discount ``gamma`` (per 50 ms control step), GAE ``gae_lambda``, PPO ``clip_range``, entropy
    bonus ``ent_coef``, value loss weight ``vf_coef``, gradient norm clip ``max_grad_norm``.
    ``net_arch``: hidden layer widths of the policy and value MLPs (separate networks, tanh).
    ``log_std_init``: initial log standard deviation of the Gaussian actions (0: std 1; a residual
    policy starts closer to its base with e.g. -1).
    """

    n_steps: int = 1024
    batch_size: int = 256
    n_epochs: int = 10
    learning_rate: float = 3e-4
    gamma: float = 0.98
    gae_lambda: float = 0.95
    clip_range: float = 0.2
    ent_coef: float = 0.0
    vf_coef: float = 0.5
    max_grad_norm: float = 0.5
    net_arch: tuple[int, ...] = (256, 256)
    log_std_init: float = 0.0

    def validate(self) -> None:
        require(self.n_steps >= 2, f"ppo.n_steps must be >= 2, got {self.n_steps}")
        require(self.batch_size >= 2, f"ppo.batch_size must be >= 2, got {self.batch_size}")
        require(self.n_epochs >= 1, f"ppo.n_epochs must be >= 1, got {self.n_epochs}")
        require(self.learning_rate > 0, f"ppo.learning_rate must be > 0, got {self.learning_rate}")
        require(0 < self.gamma <= 1, f"ppo.gamma must be in (0, 1], got {self.gamma}")
        require(0 <= self.gae_lambda <= 1, f"ppo.gae_lambda must be in [0, 1], got {self.gae_lambda}")
        require(self.clip_range > 0, f"ppo.clip_range must be > 0, got {self.clip_range}")
        require(self.ent_coef >= 0, f"ppo.ent_coef must be >= 0, got {self.ent_coef}")
        require(self.vf_coef >= 0, f"ppo.vf_coef must be >= 0, got {self.vf_coef}")
        require(self.max_grad_norm > 0, f"ppo.max_grad_norm must be > 0, got {self.max_grad_norm}")
        require(len(self.net_arch) >= 1 and all(w >= 1 for w in self.net_arch),
                f"ppo.net_arch must list >= 1 positive layer widths, got {list(self.net_arch)}")
        require(-5.0 <= self.log_std_init <= 1.0,
                f"ppo.log_std_init must be in [-5, 1], got {self.log_std_init}")


@dataclass(frozen=True)
class ResidualConfig:
    """Residual PPO on the scripted opener (agents.ppo.residual): when ``enabled``, the executed
    action is the opener's plus ``scale`` times the policy's (clipped to [-1, 1]), and the policy
    sees the opener's action and phase as well. ``opener``: the scripted opener's config, in training
    and wherever the trained policy runs (the run's ``config.yaml`` records it, so a shipped policy
    keeps the opener it learned to correct when the opener's defaults change)."""

    enabled: bool = False
    scale: float = 0.2
    opener: ScriptedOpenerConfig = field(default_factory=ScriptedOpenerConfig)

    def validate(self) -> None:
        require(0.0 < self.scale <= 2.0, f"residual.scale must be in (0, 2], got {self.scale}")
        self.opener.validate()


def _default_perception() -> PerceptionWrapperConfig:
    return PerceptionWrapperConfig(source="noisy_oracle", every_k_steps=5)


@dataclass(frozen=True)
class PPOTrainConfig:
    """What ``capt train-ppo`` trains: one category, one perception source, one PPO run.

    Envs: ``n_envs`` CPU envs of ``category`` (``pd_ee_delta_pose``, ``obs_mode``), one process
    each when ``n_envs > 1`` (``SubprocVecEnv``), in-process for 1 (``DummyVecEnv``), episodes cut
    at ``max_episode_steps`` control steps (<= 200, the task's own limit). ``task`` overrides fields
    of :class:`capt_env.tasks.TaskConfig` (placement noise, initial states, success fraction); the
    split is always ``train`` (evaluation uses the unseen ``test`` instances).
    ``perception``: the :class:`CaptObservationWrapper` config (source, noise, ``every_k_steps``);
    the default is the noisy oracle every 5 steps. ``capt`` needs ``obs_mode: pointcloud``.

    Training: ``total_timesteps`` env steps in all (over all envs; PPO stops at the end of the
    rollout that reaches it), ``ppo`` hyperparameters, global ``seed``, torch ``device``
    (``cpu`` is fastest for small MLPs), a checkpoint every ``checkpoint_every_steps`` env steps,
    and ``normalize_obs``: running mean/std observation normalisation (``VecNormalize``, saved as
    ``vecnormalize.pkl`` next to the model). ``residual``: learn corrections to the scripted
    opener instead of actions from scratch (:class:`ResidualConfig`). ``continue_after_success``:
    training episodes do not end at the task's success but run to ``max_episode_steps``
    (:class:`agents.ppo.train.ContinueAfterSuccess` says why).

    ``vec_env``: ``processes`` (the above) or ``maniskill``: all ``n_envs`` sub-scenes in one batched
    ManiSkill env (``CaptOpen*-ms-v0``) on ``sim_backend`` (``auto``: ``physx_cuda``, ManiSkill's GPU
    simulation, when ``n_envs > 1``, else ``physx_cpu``, which holds one sub-scene), observed by
    :class:`capt_env.wrappers.batched_oracle_observation.BatchedOracleObservation` and stepped by
    :class:`agents.ppo.maniskill_vec_env.ManiSkillVecEnv`. It takes the ``oracle`` or
    ``noisy_oracle`` source, ``obs_mode: state`` and no residual (the scripted opener runs per env
    in numpy). Each sub-scene holds its own train-split instance; every ``reconfigure_every_steps``
    batch steps (0: never) all episodes are cut and every sub-scene gets a new instance.
    """

    category: str = "laptop"
    perception: PerceptionWrapperConfig = field(default_factory=_default_perception)
    obs_mode: ObsMode = "state"
    n_envs: int = 1
    total_timesteps: int = 1_000_000
    ppo: PPOHyperparams = field(default_factory=PPOHyperparams)
    seed: int = 0
    device: str = "cpu"
    checkpoint_every_steps: int = 50_000
    max_episode_steps: int = MAX_EPISODE_STEPS
    task: dict[str, Any] = field(default_factory=dict)
    normalize_obs: bool = True
    residual: ResidualConfig = field(default_factory=ResidualConfig)
    continue_after_success: bool = True
    vec_env: VecEnvKind = "processes"
    sim_backend: SimBackend = "auto"
    reconfigure_every_steps: int = 0

    def validate(self) -> None:
        require(self.category in CATEGORY_ENV_NAMES,
                f"category: unknown {self.category!r}; known: {sorted(CATEGORY_ENV_NAMES)}")
        self.perception.validate()
        require(not self.perception.reads_points or self.obs_mode == "pointcloud",
                f"perception.source '{self.perception.source}' needs obs_mode: pointcloud")
        require(self.perception.obs_format == "flat",
                "perception.obs_format must be 'flat' (MlpPolicy takes the 38-float Box)")
        require(self.n_envs >= 1, f"n_envs must be >= 1, got {self.n_envs}")
        require(self.total_timesteps >= 1, f"total_timesteps must be >= 1, got {self.total_timesteps}")
        self.ppo.validate()
        self.residual.validate()
        rollout = self.ppo.n_steps * self.n_envs
        require(self.ppo.batch_size <= rollout,
                f"ppo.batch_size ({self.ppo.batch_size}) must be <= ppo.n_steps * n_envs ({rollout})")
        require(self.device in ("cpu", "cuda", "auto") or self.device.startswith("cuda:"),
                f"device must be cpu, cuda, cuda:N or auto, got {self.device!r}")
        require(self.checkpoint_every_steps >= 1,
                f"checkpoint_every_steps must be >= 1, got {self.checkpoint_every_steps}")
        require(1 <= self.max_episode_steps <= MAX_EPISODE_STEPS,
                f"max_episode_steps must be in [1, {MAX_EPISODE_STEPS}], got {self.max_episode_steps}")
        for key in ("category", "object", "joint"):
            require(key not in self.task, f"task.{key}: the object is chosen by 'category', not task")
        require(self.reconfigure_every_steps >= 0,
                f"reconfigure_every_steps must be >= 0, got {self.reconfigure_every_steps}")
        if self.vec_env == "maniskill":
            require(not self.residual.enabled, "vec_env 'maniskill' takes no residual policy (the scripted "
                    "opener runs per env in numpy): use vec_env 'processes'")
            require(self.perception.source in ("oracle", "noisy_oracle"),
                    f"vec_env 'maniskill' takes perception.source 'oracle' or 'noisy_oracle', got "
                    f"{self.perception.source!r} (CAPT runs in the per-process envs)")
            require(self.obs_mode == "state",
                    f"vec_env 'maniskill' needs obs_mode: state, got {self.obs_mode!r}")
            require(self.resolved_sim_backend() == "physx_cuda" or self.n_envs == 1,
                    f"sim_backend 'physx_cpu' holds one sub-scene; n_envs is {self.n_envs} (use physx_cuda "
                    f"on a GPU, or vec_env 'processes')")
        require(self.task.get("split", "train") == "train",
                f"task.split must be 'train' for training (test instances are for evaluation), "
                f"got {self.task.get('split')!r}")
        from_dict(TaskConfig, self.train_task() | {"category": self.category}, where="task")

    def resolved_sim_backend(self) -> str:
        """``sim_backend`` with ``auto`` resolved: ``physx_cuda`` for more than one env, else
        ``physx_cpu``."""
        if self.sim_backend != "auto":
            return self.sim_backend
        return "physx_cuda" if self.n_envs > 1 else "physx_cpu"

    def train_task(self) -> dict[str, Any]:
        """The task overrides for training envs, with the train split."""
        return {**self.task, "split": "train"}
