"""``capt rollout``: success rate of a policy with a perception source on unseen (test-split) instances."""

from __future__ import annotations

import argparse
from dataclasses import asdict
from pathlib import Path
from typing import TYPE_CHECKING, Any

from capt_common.json_report import write_json
from capt_common.typed_yaml import to_dict
from capt_env.commands.episode_log import EpisodeLog
from capt_env.commands.noise_overrides import add_noise_argument, noise_overrides, resolved_noise
from capt_env.commands.object_targets import add_object_arguments, object_targets, target_task
from capt_env.commands.task_overrides import add_task_argument, task_overrides

if TYPE_CHECKING:
    from agents.scripted.config import ScriptedOpenerConfig
    from agents.scripted.rollout import EpisodeResult


def add_arguments(parser: argparse.ArgumentParser) -> None:
    add_object_arguments(parser, ["cabinet_door"])
    parser.add_argument("--policy", default="scripted", choices=["scripted", "ppo"],
                        help="the policy to evaluate")
    parser.add_argument("--model", default=None,
                        help="PPO model .zip (with --policy ppo; default: the category's shipped policy)")
    parser.add_argument("--perception", nargs="+", default=["oracle"],
                        choices=["oracle", "noisy_oracle", "capt_raw", "capt"],
                        help="perception sources to compare (capt_raw: the network alone; capt: refined)")
    parser.add_argument("--checkpoint", default=None, help="CAPT checkpoint (default: the shipped one)")
    parser.add_argument("--episodes", type=int, default=10, help="episodes per category and source")
    parser.add_argument("--first-seed", type=int, default=0, help="episodes use seeds first..first+n-1")
    parser.add_argument("--every-k-steps", type=int, default=5, help="perception period in env steps")
    parser.add_argument("--max-steps", type=int, default=200, help="control steps per episode (20 Hz)")
    parser.add_argument("--opener", default=None,
                        help="YAML of ScriptedOpenerConfig overrides (with --policy scripted), e.g. "
                             "configs/opener/steep_door_approach.yaml; default: the opener's defaults")
    add_noise_argument(parser)
    add_task_argument(parser)
    parser.add_argument("--markdown", default=None, help="also write the table as Markdown here")
    parser.add_argument("--workers", type=int, default=1,
                        help="processes that play episodes side by side (each with its own env and "
                             "policy, torch on one thread); the episodes do not depend on it")
    parser.add_argument("--episode-log", default=None,
                        help="JSON-lines file: every episode is appended as it ends, and the episodes "
                             "already there for the same evaluation are not played again (resume an "
                             "interrupted run by repeating its command)")


def opener_config(path: str | None) -> ScriptedOpenerConfig:
    """The scripted opener's config: its defaults, overridden by the keys of YAML ``path`` (unknown
    keys and bad values exit with a message naming them)."""
    from agents.scripted.config import ScriptedOpenerConfig
    from capt_common.typed_yaml import ConfigError, load_yaml
    from capt_env.shipped_configs import resolve_config

    if path is None:
        return ScriptedOpenerConfig()
    try:
        return load_yaml(ScriptedOpenerConfig, resolve_config("opener", path))
    except (ConfigError, FileNotFoundError) as err:
        raise SystemExit(f"--opener {path}: {err}") from err


def ppo_model(args: argparse.Namespace, category: str) -> str | None:
    """The PPO model file to evaluate (``--model``, else the category's shipped policy); None for the
    scripted opener."""
    if args.policy != "ppo":
        return None
    from agents.ppo.policies import shipped_policy

    try:
        return str(args.model or shipped_policy(category))
    except FileNotFoundError as err:
        raise SystemExit(str(err)) from err


def success_row(episodes: list[EpisodeResult]) -> dict[str, Any]:
    """Success rate with its Wilson 95% interval, mean opened fraction and mean steps of
    ``episodes``, and the episodes themselves."""
    import numpy as np

    from agents.success_stats import wilson_interval

    wins = sum(e.success for e in episodes)
    lo, hi = wilson_interval(wins, len(episodes))
    return {"success_rate": wins / len(episodes), "ci95": [lo, hi],
            "mean_open_fraction": float(np.mean([e.open_fraction for e in episodes])),
            "mean_steps": float(np.mean([e.steps for e in episodes])),
            "episodes": [asdict(e) for e in episodes]}


def success_cells(row: dict[str, Any]) -> str:
    """The Markdown cells ``success | 95% interval | mean opened | mean steps | episodes`` of a
    :func:`success_row`."""
    lo, hi = row["ci95"]
    return (f"{row['success_rate']:.2f} | [{lo:.2f}, {hi:.2f}] | {row['mean_open_fraction']:.2f} | "
            f"{row['mean_steps']:.0f} | {len(row['episodes'])}")


def cause_row(episodes: list[EpisodeResult]) -> dict[str, Any]:
    """``{"failure_causes": {cause: count}}``: the failed episodes of ``episodes`` counted by the
    cause named from the scripted opener's phase log (:mod:`agents.scripted.failure_cause`; empty for a
    policy that keeps no phase log)."""
    from agents.scripted.failure_cause import count_causes

    causes = [e.cause for e in episodes]
    return {"failure_causes": count_causes(causes) if any(c is not None for c in causes) else {}}


def cause_cell(row: dict[str, Any]) -> str:
    """The Markdown cell of a :func:`cause_row`: ``cause count`` for each cause that occurred,
    comma-separated; ``-`` for none."""
    counts = row["failure_causes"]
    return ", ".join(f"{cause} {n}" for cause, n in counts.items() if n) or "-"


def run(args: argparse.Namespace) -> int:
    from capt_env.commands.episode_runner import EpisodeJob, play_episodes

    header = ("| object | perception | model | success | 95% interval | mean opened | mean steps | "
              "episodes | failures by cause |")
    rows, lines = [], [header, "| --- | --- | --- | --- | --- | --- | --- | --- | --- |"]
    targets = object_targets(args)
    seeds = list(range(args.first_seed, args.first_seed + args.episodes))
    task = task_overrides(args.task)
    if args.opener is not None and args.policy != "scripted":
        raise SystemExit("--opener configures the scripted policy; a PPO policy runs the opener "
                         "recorded with it")
    opener = opener_config(args.opener) if args.policy == "scripted" else None
    if args.workers < 1:
        raise SystemExit(f"--workers must be at least 1, got {args.workers}")
    if args.episodes < 1:
        raise SystemExit(f"--episodes must be at least 1, got {args.episodes}")
    noise = noise_overrides(args.noise)
    if args.noise and "noisy_oracle" not in args.perception:
        raise SystemExit("--noise sets the noisy_oracle source's noise; add noisy_oracle to --perception")
    for target in targets:
        like = target.model_category()
        for source in args.perception:
            wrapper: dict[str, Any] = {"source": source, "every_k_steps": args.every_k_steps}
            if source == "noisy_oracle":
                wrapper["noise"] = noise
            obs_mode = "state"
            if source in ("capt_raw", "capt"):
                from perception.checkpoints import default_checkpoint

                wrapper["checkpoint"] = str(args.checkpoint or default_checkpoint(like))
                obs_mode = "pointcloud"
            model = ppo_model(args, like)
            job = EpisodeJob(target.category, wrapper, target_task(target, task), obs_mode, args.policy,
                             model, opener, args.max_steps)
            log = None if args.episode_log is None else EpisodeLog(args.episode_log, job.identity())
            episodes = play_episodes(job, seeds, args.workers, log, desc=f"{target.label} {source}")
            used = Path(wrapper["checkpoint"]).stem if "checkpoint" in wrapper else model and Path(model).stem
            row = {"object": target.label, "category": target.category, "task": job.task,
                   "policy": args.policy, "model": model, "perception": source,
                   "checkpoint": wrapper.get("checkpoint"), "like": like,
                   **cause_row(episodes), **success_row(episodes)}
            rows.append(row)
            lines.append(f"| {target.label} | {source} | {used or '-'} | {success_cells(row)} | "
                         f"{cause_cell(row)} |")
    table = "\n".join(lines)
    print(table)
    if args.markdown:
        Path(args.markdown).parent.mkdir(parents=True, exist_ok=True)
        Path(args.markdown).write_text(table + "\n")
    write_json(args.json, {"seeds": seeds, "policy": args.policy, "max_steps": args.max_steps,
                           "workers": args.workers,
                           "every_k_steps": args.every_k_steps, "task": task,
                           "noise": resolved_noise(noise) if "noisy_oracle" in args.perception else None,
                           "opener": None if opener is None else to_dict(opener),
                           "results": rows})
    return 0
