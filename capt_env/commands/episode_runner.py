"""Play a policy's evaluation episodes, in this process or in worker processes, logged as they end.

Every episode is fully determined by its seed (the env rebuilds its instance and seeds the
wrapper's downsampling and noise from it, the policy is reset), so the seeds can be shared out
among processes and the episodes come out the same as when played one after another. One caveat:
a worker runs torch on one thread, and a CAPT network's floating-point sums on one thread may
round differently from the same sums on several, which can flip an episode at the margin.
"""

from __future__ import annotations

import multiprocessing
from collections.abc import Iterator
from dataclasses import asdict, dataclass
from typing import TYPE_CHECKING, Any

if TYPE_CHECKING:
    from agents.scripted.config import ScriptedOpenerConfig
    from agents.scripted.rollout import EpisodeResult
    from capt_env.commands.episode_log import EpisodeLog


@dataclass(frozen=True)
class EpisodeJob:
    """What a process needs to play episodes: the category and split overrides (``task``), the
    perception wrapper's config (a dict of :class:`PerceptionWrapperConfig` fields), the env's obs
    mode, the policy (``scripted`` with ``opener``, or ``ppo`` with the ``model`` file) and the step
    limit."""

    category: str | None  # None: the user file in task["object"]
    wrapper: dict[str, Any]
    task: dict[str, Any]
    obs_mode: str
    policy: str
    model: str | None
    opener: ScriptedOpenerConfig | None
    max_steps: int

    def identity(self) -> dict[str, Any]:
        """What makes two evaluations the same (the key of :class:`EpisodeLog` records): everything
        that decides an episode given its seed."""
        from capt_common.typed_yaml import from_dict, to_dict
        from capt_env.wrappers.config import NoiseConfig

        identity = {"category": self.category, "policy": self.policy, "model": self.model,
                    "perception": self.wrapper["source"], "checkpoint": self.wrapper.get("checkpoint"),
                    "every_k_steps": self.wrapper["every_k_steps"], "max_steps": self.max_steps,
                    "task": self.task, "opener": None if self.opener is None else to_dict(self.opener)}
        if self.wrapper["source"] == "noisy_oracle":  # every field, so a changed default is a new run
            identity["noise"] = to_dict(from_dict(NoiseConfig, self.wrapper.get("noise", {}), where="noise"))
        return identity

    def build(self) -> tuple[Any, Any]:
        """A fresh wrapped env and policy."""
        from capt_env.env_factory import make_env

        if self.policy == "ppo":
            from agents.ppo.policy import PPOPolicy

            assert self.model is not None
            policy: Any = PPOPolicy.load(self.model)
        else:
            from agents.scripted.opener import ScriptedOpener

            policy = ScriptedOpener(self.opener)
        return make_env(self.category, self.wrapper, task=self.task, obs_mode=self.obs_mode), policy


_worker: dict[str, Any] = {}  # the env and policy of a worker process


def _start_worker(job: EpisodeJob) -> None:
    import torch

    torch.set_num_threads(1)  # the processes share the cores
    _worker["job"] = job
    _worker["env"], _worker["policy"] = job.build()


def _play_in_worker(seed: int) -> EpisodeResult:
    from agents.scripted.rollout import run_episode

    return run_episode(_worker["env"], _worker["policy"], seed, _worker["job"].max_steps)


def _played(job: EpisodeJob, seeds: list[int], workers: int) -> Iterator[EpisodeResult]:
    """The episodes of ``seeds``, in the order they end."""
    if not seeds:
        return
    if workers <= 1:
        from agents.scripted.rollout import run_episode

        env, policy = job.build()
        try:
            for seed in seeds:
                yield run_episode(env, policy, seed, job.max_steps)
        finally:
            env.close()
        return
    # spawn: SAPIEN and torch hold threads and device handles that a forked child must not inherit
    context = multiprocessing.get_context("spawn")
    with context.Pool(min(workers, len(seeds)), initializer=_start_worker, initargs=(job,)) as pool:
        yield from pool.imap_unordered(_play_in_worker, seeds)


def play_episodes(job: EpisodeJob, seeds: list[int], workers: int = 1, log: EpisodeLog | None = None,
                  desc: str = "") -> list[EpisodeResult]:
    """One episode per seed, returned in the order of ``seeds``, played by ``workers`` processes
    (1: this one). With ``log``, each episode is appended to it as it ends, and the seeds it already
    holds for this evaluation are read back instead of played. Progress bar on stderr."""
    from tqdm import tqdm

    from agents.scripted.rollout import EpisodeResult

    if workers < 1:
        raise ValueError(f"workers must be >= 1, got {workers}")
    done: dict[int, EpisodeResult] = {}
    if log is not None:
        for seed in seeds:
            recorded = log.recorded(seed)
            if recorded is not None:
                done[seed] = EpisodeResult(**recorded)
        if done:
            print(f"{desc}: {len(done)} of {len(seeds)} episodes read back from {log.path}")
    pending = [s for s in seeds if s not in done]
    with tqdm(total=len(seeds), initial=len(done), desc=desc) as bar:
        for episode in _played(job, pending, workers):
            if log is not None:
                log.append(asdict(episode))
            done[episode.seed] = episode
            bar.update(1)
    return [done[s] for s in seeds]
