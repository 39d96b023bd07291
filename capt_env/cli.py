"""The ``capt`` command line: one console script, one verb per job.

Every verb prints a human summary and, with ``--json PATH``, writes its numbers as JSON. Verbs import
their heavy dependencies lazily, so ``capt --help`` and ``capt doctor`` stay fast.
"""

from __future__ import annotations

import argparse
import importlib
import sys

# verb -> (module under capt_env.commands, one-line help)
VERBS: dict[str, tuple[str, str]] = {
    "doctor": ("doctor", "rendering device SAPIEN sees, versions, and what to install"),
    "demo": ("demo", "the main job: estimate unseen objects' joints with CAPT, then open them"),
    "generate": ("generate", "render a labelled point-cloud dataset of one category as shards"),
    "train": ("train", "train a CAPT variant (capt, capt_plain, pct_regression) on a generated dataset"),
    "evaluate": ("evaluate", "the paper's Table I and time per input for checkpoints, side by side"),
    "train-ppo": ("train_ppo", "train PPO on joint-axis observations (train split), resumable"),
    "rollout": ("rollout", "success rate of the scripted policy per category and perception source"),
    "noise-sweep": ("noise_sweep", "success rate against the size of one joint-estimate error"),
    "estimate-errors": ("estimate_errors", "errors of the wrapper's CAPT estimate on unseen env resets"),
    "inspect-object": ("inspect_object", "check a user's URDF/MJCF file: joints, front, reach, a PNG"),
    "bench": ("bench", "environment speed: steps/s in state and pointcloud mode, reset time"),
}


def build_parser() -> argparse.ArgumentParser:
    parser = argparse.ArgumentParser(prog="capt", description=__doc__.splitlines()[0])
    sub = parser.add_subparsers(dest="verb", required=True, metavar="VERB")
    for verb, (module, help_text) in VERBS.items():
        mod = importlib.import_module(f"capt_env.commands.{module}")
        p = sub.add_parser(verb, help=help_text, description=help_text)
        mod.add_arguments(p)
        p.add_argument("--json", metavar="PATH", default=None, help="also write the numbers as JSON here")
        p.set_defaults(_run=mod.run)
    return parser


def main(argv: list[str] | None = None) -> int:
    args = build_parser().parse_args(argv)
    try:
        return int(args._run(args) or 0)
    except KeyboardInterrupt:
        print("interrupted", file=sys.stderr)
        return 130


if __name__ == "__main__":
    sys.exit(main())
