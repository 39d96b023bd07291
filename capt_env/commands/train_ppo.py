"""``capt train-ppo``: train SB3 PPO on joint-axis observations (see agents.ppo.train), resumable."""

from __future__ import annotations

import argparse

from capt_common.json_report import write_json


def add_arguments(parser: argparse.ArgumentParser) -> None:
    parser.add_argument("--config", default="laptop",
                        help="PPOTrainConfig: a shipped name (laptop, drawer_cabinet, ...) or a YAML path")
    parser.add_argument("--out", required=True, help="run directory: checkpoints/, logs/, final.zip")
    parser.add_argument("--total-timesteps", type=int, default=None,
                        help="override the config's total env steps (a resume continues up to it)")
    parser.add_argument("--device", default=None, help="cpu, cuda[:i] or auto (default: the config's)")
    parser.add_argument("--no-resume", action="store_true",
                        help="start over even if OUT has checkpoints")
    parser.add_argument("--quiet", action="store_true", help="no SB3 table after each rollout")


def _fmt(value: float | None, spec: str) -> str:
    return "n/a" if value is None else format(value, spec)


def run(args: argparse.Namespace) -> int:
    from agents.ppo.config import PPOTrainConfig
    from agents.ppo.train import train_ppo
    from capt_common.typed_yaml import ConfigError, from_dict, load_yaml, to_dict
    from capt_env.shipped_configs import resolve_config

    cfg = to_dict(load_yaml(PPOTrainConfig, resolve_config("ppo", args.config)))
    if args.total_timesteps is not None:
        cfg["total_timesteps"] = args.total_timesteps
    if args.device is not None:
        cfg["device"] = args.device
    try:
        config = from_dict(PPOTrainConfig, cfg)
        summary = train_ppo(config, args.out, resume=not args.no_resume, log_to_stdout=not args.quiet)
    except ConfigError as err:
        raise SystemExit(f"error: {err}") from err
    resumed = f" (resumed from {summary['resumed_from']})" if summary["resumed_from"] else ""
    print(f"{config.category} PPO, perception {config.perception.source}, {config.n_envs} env(s){resumed}")
    print(f"  steps: {summary['num_timesteps']} in all, {summary['steps_this_run']} this run in "
          f"{summary['wall_time_s']:.1f} s ({_fmt(summary['steps_per_s'], '.0f')} steps/s)")
    print(f"  last {summary['episodes_in_stats']} episodes: mean reward "
          f"{_fmt(summary['mean_episode_reward'], '.3f')}, mean length "
          f"{_fmt(summary['mean_episode_length'], '.0f')}, success {_fmt(summary['success_rate'], '.2f')}")
    formats = ", ".join(summary["logger_formats"])
    print(f"  model: {summary['final_model']}; logs: {summary['log_dir']} ({formats})")
    write_json(args.json, {"config": to_dict(config), "summary": summary})
    return 0
