"""Run the scripted opener in a wrapped capt_env env and measure its success rate.

``python -m agents.scripted.rollout --category drawer_cabinet --episodes 10`` prints per-episode
results and the success rate. Episodes use the test split (unseen shapes) and seeds 0..episodes-1.
"""

from __future__ import annotations

import argparse
import json
from dataclasses import asdict, dataclass
from typing import Any

import gymnasium as gym
import numpy as np

from agents.scripted.config import ScriptedOpenerConfig
from agents.scripted.opener import Phase, ScriptedOpener
from capt_env.registration import GENERIC_ID, env_id
from capt_env.wrappers.config import PerceptionWrapperConfig
from capt_env.wrappers.perception_wrapper import CaptObservationWrapper


@dataclass(frozen=True)
class EpisodeResult:
    """One episode: the seed, instance, success (task's criterion at the end), final open fraction,
    steps taken, and the opener's last phase."""

    seed: int
    instance_id: int
    success: bool
    open_fraction: float
    steps: int
    phase: str


def make_env(category: str | None, wrapper: PerceptionWrapperConfig | dict | None = None,
             task: dict | None = None, obs_mode: str = "state", **kwargs: Any) -> CaptObservationWrapper:
    """A ``pd_ee_delta_pose`` env wrapped for the opener: of ``category`` (test split by default),
    or, with ``category`` None, of the user file ``task["object"]``."""
    kwargs.setdefault("control_mode", "pd_ee_delta_pose")
    if category is None:
        if not (task or {}).get("object"):
            raise ValueError("make_env needs a category or a task with an 'object' file")
        env = gym.make(GENERIC_ID, obs_mode=obs_mode, task=dict(task), **kwargs)
        return CaptObservationWrapper(env, wrapper)
    task_cfg = {"split": "test", **(task or {})}
    env = gym.make(env_id(category), obs_mode=obs_mode, task=task_cfg, **kwargs)
    return CaptObservationWrapper(env, wrapper)


def run_episode(env: CaptObservationWrapper, opener: Any, seed: int, max_steps: int = 200,
                settle_steps: int = 10) -> EpisodeResult:
    """One episode of any policy with ``reset()`` and ``act(obs, info)`` (the scripted opener or a PPO
    policy); with the scripted opener it ends ``settle_steps`` after the opener is done (so the part
    comes to rest)."""
    obs, info = env.reset(seed=seed)
    opener.reset()
    steps, done_for = 0, 0
    for steps in range(1, max_steps + 1):  # noqa: B007
        obs, _, terminated, truncated, info = env.step(opener.act(obs, info))
        done_for = done_for + 1 if getattr(opener, "phase", None) == Phase.DONE else 0
        if done_for >= settle_steps or truncated:
            break
    obj = env.unwrapped.object
    return EpisodeResult(seed, int(obj.instance_id), bool(info["success"]), float(info["open_fraction"]),
                         steps, getattr(getattr(opener, "phase", None), "value", "policy"))


def success_rate(category: str, seeds: list[int], wrapper: PerceptionWrapperConfig | dict | None = None,
                 opener: ScriptedOpenerConfig | None = None, max_steps: int = 200,
                 task: dict | None = None) -> tuple[float, list[EpisodeResult]]:
    """Share of successful episodes of ``category`` over ``seeds``, and the episodes."""
    env = make_env(category, wrapper, task)
    policy = ScriptedOpener(opener)
    try:
        results = [run_episode(env, policy, s, max_steps) for s in seeds]
    finally:
        env.close()
    return float(np.mean([r.success for r in results])), results


def main(argv: list[str] | None = None) -> None:
    parser = argparse.ArgumentParser(description=__doc__)
    parser.add_argument("--category", required=True)
    parser.add_argument("--episodes", type=int, default=10)
    parser.add_argument("--first-seed", type=int, default=0)
    parser.add_argument("--source", default="oracle", choices=["oracle", "noisy_oracle"])
    parser.add_argument("--max-steps", type=int, default=200)
    parser.add_argument("--json", default=None)
    args = parser.parse_args(argv)
    seeds = list(range(args.first_seed, args.first_seed + args.episodes))
    rate, results = success_rate(args.category, seeds, {"source": args.source}, max_steps=args.max_steps)
    for r in results:
        print(json.dumps(asdict(r)))
    print(f"{args.category}: success {rate:.2f} over {len(results)} episodes (seeds {seeds[0]}..{seeds[-1]})")
    if args.json:
        with open(args.json, "w") as fh:
            json.dump({"category": args.category, "success_rate": rate,
                       "episodes": [asdict(r) for r in results]}, fh, indent=1)


if __name__ == "__main__":
    main()
