"""``capt noise-sweep``: success rate against the size of one joint-estimate error.

The policy acts on the ``noisy_oracle`` source: ground truth with one error parameter swept over
``--values`` and every other error zero (unless set with ``--noise``). With the default
``fixed_offset`` model each episode's estimate is off by exactly that much (random direction and
sign, held for the episode), so the table reads as "success when the axis is off by X", the curve a
perception error has to be judged against. Episodes are on unseen (test-split) instances with fixed
seeds, the same seeds for every value.
"""

from __future__ import annotations

import argparse
import math
from typing import Any

from capt_env.commands.noise_overrides import add_noise_argument, check_noise, noise_overrides, resolved_noise
from capt_env.commands.task_overrides import add_task_argument, task_overrides

# swept parameter -> (NoiseConfig field, factor from the parameter's unit to the field's, unit, label)
PARAMETERS: dict[str, tuple[str, float, str, str]] = {
    "direction_deg": ("direction_rad", math.pi / 180.0, "deg", "axis direction error"),
    "pivot_m": ("pivot_m", 1.0, "m", "axis line offset"),
    "state": ("state", 1.0, "rad or m", "state error"),
    "grasp_m": ("grasp_m", 1.0, "m", "grasp point error"),
    "grasp_outward_m": ("grasp_outward_m", 1.0, "m", "grasp point outward bias"),
}


def add_arguments(parser: argparse.ArgumentParser) -> None:
    parser.add_argument("--categories", nargs="+", default=["laptop"], help="object categories")
    parser.add_argument("--parameter", required=True, choices=sorted(PARAMETERS),
                        help="the error swept: axis direction (degrees), axis line offset (metres), "
                             "state (radians for revolute, metres for prismatic joints), grasp point "
                             "(metres, random direction), grasp point outward bias (metres)")
    parser.add_argument("--values", nargs="+", type=float, required=True,
                        help="sizes of the swept error, in the parameter's unit")
    parser.add_argument("--noise-model", default="fixed_offset", choices=["fixed_offset", "gaussian"],
                        help="fixed_offset: exactly that error, held for the episode; gaussian: that "
                             "std, redrawn at every estimate")
    parser.add_argument("--policy", default="scripted", choices=["scripted", "ppo"],
                        help="the policy to evaluate")
    parser.add_argument("--model", default=None,
                        help="PPO model .zip (with --policy ppo; default: the category's shipped policy)")
    parser.add_argument("--opener", default=None,
                        help="YAML of ScriptedOpenerConfig overrides (with --policy scripted)")
    parser.add_argument("--episodes", type=int, default=20, help="episodes per category and value")
    parser.add_argument("--first-seed", type=int, default=0, help="episodes use seeds first..first+n-1")
    parser.add_argument("--every-k-steps", type=int, default=5, help="perception period in env steps")
    parser.add_argument("--max-steps", type=int, default=200, help="control steps per episode (20 Hz)")
    add_noise_argument(parser)
    add_task_argument(parser)
    parser.add_argument("--markdown", default=None, help="also write the table as Markdown here")
    parser.add_argument("--workers", type=int, default=1,
                        help="processes that play episodes side by side; the episodes do not depend on it")
    parser.add_argument("--episode-log", default=None,
                        help="JSON-lines file of finished episodes; repeating the command resumes")


def sweep_noise(parameter: str, value: float, model: str, base: dict[str, Any]) -> dict[str, Any]:
    """NoiseConfig overrides for one sweep point: every error field zero, then ``base`` (the
    ``--noise`` overrides), then the swept field set to ``value`` converted from the parameter's unit."""
    if parameter not in PARAMETERS:
        raise ValueError(f"unknown parameter {parameter!r}; choose from {sorted(PARAMETERS)}")
    field, factor = PARAMETERS[parameter][:2]
    if field in base:
        raise SystemExit(f"--noise sets {field}, which --parameter {parameter} sweeps")
    zero = {spec[0]: 0.0 for spec in PARAMETERS.values()}
    return {**zero, **base, "model": model, field: value * factor}


def sweep_table(parameter: str, rows: list[dict[str, Any]]) -> str:
    """The Markdown table of a sweep's result rows (one per category and value)."""
    from capt_env.commands.rollout import success_cells

    _, _, unit, label = PARAMETERS[parameter]
    lines = [f"| category | {label} ({unit}) | success | 95% interval | mean opened | mean steps | "
             "episodes |", "| --- | --- | --- | --- | --- | --- | --- |"]
    lines += [f"| {r['category']} | {r['value']:g} | {success_cells(r)} |" for r in rows]
    return "\n".join(lines)


def run(args: argparse.Namespace) -> int:
    from pathlib import Path

    from capt_common.json_report import write_json
    from capt_common.typed_yaml import to_dict
    from capt_env.commands.episode_log import EpisodeLog
    from capt_env.commands.episode_runner import EpisodeJob, play_episodes
    from capt_env.commands.rollout import opener_config, ppo_model, success_row

    if args.episodes < 1:
        raise SystemExit(f"--episodes must be at least 1, got {args.episodes}")
    if args.workers < 1:
        raise SystemExit(f"--workers must be at least 1, got {args.workers}")
    if any(not math.isfinite(v) or v < 0 for v in args.values):
        raise SystemExit(f"--values must be finite and >= 0, got {args.values}")
    if args.opener is not None and args.policy != "scripted":
        raise SystemExit("--opener configures the scripted policy")
    base = noise_overrides(args.noise)
    if "model" in base:
        raise SystemExit("--noise model=... is --noise-model here")
    noises = [sweep_noise(args.parameter, v, args.noise_model, base) for v in args.values]
    for noise in noises:  # every sweep point's config is valid before any episode is played
        check_noise(noise)
    unit = PARAMETERS[args.parameter][2]
    task = task_overrides(args.task)
    opener = opener_config(args.opener) if args.policy == "scripted" else None
    seeds = list(range(args.first_seed, args.first_seed + args.episodes))
    rows = []
    for category in args.categories:
        model = ppo_model(args, category)
        for value, noise in zip(args.values, noises, strict=True):
            wrapper = {"source": "noisy_oracle", "every_k_steps": args.every_k_steps, "noise": noise}
            job = EpisodeJob(category, wrapper, task, "state", args.policy, model, opener, args.max_steps)
            log = None if args.episode_log is None else EpisodeLog(args.episode_log, job.identity())
            episodes = play_episodes(job, seeds, args.workers, log,
                                     desc=f"{category} {args.parameter}={value:g}")
            row = {"category": category, "policy": args.policy, "model": model,
                   "parameter": args.parameter, "value": value, "noise": resolved_noise(noise),
                   **success_row(episodes)}
            rows.append(row)
    table = sweep_table(args.parameter, rows)
    print(table)
    if args.markdown:
        Path(args.markdown).parent.mkdir(parents=True, exist_ok=True)
        Path(args.markdown).write_text(table + "\n")
    write_json(args.json, {"seeds": seeds, "policy": args.policy, "parameter": args.parameter,
                           "unit": unit, "values": args.values, "noise_model": args.noise_model,
                           "max_steps": args.max_steps, "every_k_steps": args.every_k_steps,
                           "workers": args.workers, "task": task,
                           "opener": None if opener is None else to_dict(opener), "results": rows})
    return 0
