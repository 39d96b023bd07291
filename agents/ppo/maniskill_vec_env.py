"""An SB3 ``VecEnv`` over one batched ManiSkill env: PPO on ManiSkill's GPU simulation.

All sub-scenes step in one process (``CaptOpen*-ms-v0`` with ``num_envs`` sub-scenes, GPU physics
with ``sim_backend="physx_cuda"``), behind :class:`~capt_env.wrappers.batched_oracle_observation.
BatchedOracleObservation`; this class turns its batched torch tensors into what SB3 expects (numpy
arrays, one info dict per env) and does what ``Monitor`` and the auto-reset of SB3's own vector
envs do: an ended sub-scene is reset on its own (a partial reset), its last observation goes to
``info["terminal_observation"]``, and ``info["episode"]`` holds its return ``r``, length ``l`` and
the task's ``success`` at its last step (what ``agents.ppo.train.episode_stats`` reads).

With ``continue_after_success`` an episode does not end at the task's success but runs to the step
limit (``agents.ppo.train.ContinueAfterSuccess`` says why).

With more than one sub-scene each sub-scene holds its own object instance, drawn from the task's
split by that sub-scene's episode RNG (:mod:`capt_env.tasks.object_batch`), and a partial reset
keeps it; a seeded ``reset`` (after ``seed(s)``, as SB3 does) rebuilds every sub-scene, so the
instances follow the seeds. ``reconfigure_every`` > 0 cuts every episode (as truncated, so PPO
bootstraps them) once that many steps have passed since the last reconfiguration, and resets all
sub-scenes with ``reconfigure=True``: a new instance for every sub-scene.
"""

from __future__ import annotations

from collections.abc import Sequence
from typing import Any

import gymnasium as gym
import numpy as np
import torch
from stable_baselines3.common.vec_env.base_vec_env import VecEnv, VecEnvIndices, VecEnvObs, VecEnvStepReturn


class ManiSkillVecEnv(VecEnv):
    """SB3 vector env over a batched env whose ``reset``/``step`` take and give (num_envs, ...) tensors.

    :param env: e.g. ``BatchedOracleObservation(gym.make("CaptOpenLaptop-ms-v0", num_envs=256, ...))``;
        it must declare ``single_observation_space`` and ``single_action_space``, and its ``info``
        must carry ``success`` ((num_envs,) bool).
    :param continue_after_success: ignore terminations that come with success.
    :param reconfigure_every: steps (of the batch) between new object instances; 0 never.
    """

    def __init__(self, env: gym.Env, continue_after_success: bool = True, reconfigure_every: int = 0) -> None:
        if reconfigure_every < 0:
            raise ValueError(f"reconfigure_every must be >= 0, got {reconfigure_every}")
        self.env = env
        base = env.unwrapped
        super().__init__(int(base.num_envs), env.get_wrapper_attr("single_observation_space"),
                         env.get_wrapper_attr("single_action_space"))
        self.device = torch.device(base.device)
        self.continue_after_success = continue_after_success
        self.reconfigure_every = reconfigure_every
        self._since_reconfigure = 0
        self._returns = torch.zeros(self.num_envs, dtype=torch.float64, device=self.device)
        self._lengths = torch.zeros(self.num_envs, dtype=torch.long, device=self.device)
        self._actions: torch.Tensor | None = None

    def reset(self) -> VecEnvObs:
        seeds = [s for s in self._seeds if s is not None]
        seed = [int(s) for s in self._seeds] if len(seeds) == self.num_envs else None
        # seeded: rebuild, so that each sub-scene's instance follows its seed (the env was built with
        # ManiSkill's fixed construction seeds)
        obs, _ = self.env.reset(seed=seed, options={"reconfigure": True} if seed is not None else None)
        self._reset_seeds()
        self._since_reconfigure = 0
        self._returns.zero_()
        self._lengths.zero_()
        return obs.cpu().numpy()

    def step_async(self, actions: np.ndarray) -> None:
        self._actions = torch.as_tensor(np.asarray(actions), dtype=torch.float32, device=self.device)

    def step_wait(self) -> VecEnvStepReturn:
        assert self._actions is not None, "step_async before step_wait"
        obs, reward, terminated, truncated, info = self.env.step(self._actions)
        reward = torch.as_tensor(reward, device=self.device).reshape(-1)
        success = torch.as_tensor(info["success"], device=self.device).reshape(-1).bool()
        terminated = torch.as_tensor(terminated, device=self.device).reshape(-1).bool()
        truncated = torch.as_tensor(truncated, device=self.device).reshape(-1).bool()
        if self.continue_after_success:
            terminated = terminated & ~success
        self._returns += reward.double()
        self._lengths += 1
        self._since_reconfigure += 1
        reconfigure = 0 < self.reconfigure_every <= self._since_reconfigure
        if reconfigure:
            truncated = torch.ones_like(truncated)
        done = terminated | truncated
        obs_np = obs.cpu().numpy()
        infos: list[dict[str, Any]] = [{} for _ in range(self.num_envs)]
        if bool(done.any()):
            ended = torch.nonzero(done).reshape(-1)
            for i in ended.tolist():
                infos[i] = {"terminal_observation": obs_np[i].copy(),
                            "TimeLimit.truncated": bool(truncated[i] and not terminated[i]),
                            "episode": {"r": float(self._returns[i]), "l": int(self._lengths[i]),
                                        "success": bool(success[i])}}
            if reconfigure:
                new_obs, _ = self.env.reset(options={"reconfigure": True})
                self._since_reconfigure = 0
            else:
                new_obs, _ = self.env.reset(options={"env_idx": ended})
            obs_np[ended.cpu().numpy()] = new_obs[ended].cpu().numpy()
            self._returns[ended] = 0.0
            self._lengths[ended] = 0
        return obs_np, reward.float().cpu().numpy(), done.cpu().numpy(), infos

    def close(self) -> None:
        self.env.close()

    def _indices(self, indices: VecEnvIndices) -> Sequence[int]:
        if indices is None:
            return range(self.num_envs)
        return [indices] if isinstance(indices, int) else list(indices)

    def get_attr(self, attr_name: str, indices: VecEnvIndices = None) -> list[Any]:
        value = self.env.get_wrapper_attr(attr_name)
        return [value for _ in self._indices(indices)]

    def set_attr(self, attr_name: str, value: Any, indices: VecEnvIndices = None) -> None:
        raise NotImplementedError("the sub-scenes share one env: set attributes on it directly")

    def env_method(self, method_name: str, *method_args: Any, indices: VecEnvIndices = None,
                   **method_kwargs: Any) -> list[Any]:
        raise NotImplementedError("the sub-scenes share one env: call its methods directly")

    def env_is_wrapped(self, wrapper_class: type[gym.Wrapper], indices: VecEnvIndices = None) -> list[bool]:
        return [False for _ in self._indices(indices)]
