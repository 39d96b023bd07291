"""The ``capt`` command line: one console script, one verb per job.

Every verb prints a human summary and, with ``--json PATH``, writes its numbers as JSON. Only the
chosen verb's module is imported, and verbs import their heavy dependencies lazily, so ``capt
--help`` stays fast. Bad input (a missing file, a bad config value, an unknown category) is one line
``capt VERB: error: ...`` and exit status 2, as argparse reports bad options.
"""

from __future__ import annotations

import argparse
import importlib
import os
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
    "bench": ("bench", "speed: env steps/s per obs mode, env + CAPT on both render paths, CAPT per cloud"),
}


class DefaultsHelpFormatter(argparse.ArgumentDefaultsHelpFormatter):
    """argparse's defaults formatter, except where the help already says what the default is (a
    default of None that means "the config's" or "the shipped one" is stated in words)."""

    def _get_help_string(self, action: argparse.Action) -> str | None:
        text = action.help or ""
        return text if "(default" in text or "; default" in text else super()._get_help_string(action)


def _add_verb(sub: argparse._SubParsersAction, verb: str, with_arguments: bool) -> None:
    module, help_text = VERBS[verb]
    p = sub.add_parser(verb, help=help_text, description=help_text,
                       formatter_class=DefaultsHelpFormatter)
    if not with_arguments:
        return
    mod = importlib.import_module(f"capt_env.commands.{module}")
    mod.add_arguments(p)
    from capt_env.commands.deprecated_flags import apply_deprecated_flags

    apply_deprecated_flags(p, verb)  # old spellings: hidden, warn, still work for one release
    p.add_argument("--json", metavar="PATH", default=None, help="also write the numbers as JSON here")
    p.set_defaults(_run=mod.run)


def build_parser(verbs: list[str] | None = None) -> argparse.ArgumentParser:
    """The ``capt`` parser; only the verbs in ``verbs`` (default: all) get their options, so that
    ``capt --help`` and one verb's parsing import nothing else."""
    parser = argparse.ArgumentParser(prog="capt", description=__doc__.splitlines()[0])
    sub = parser.add_subparsers(dest="verb", required=True, metavar="VERB")
    chosen = set(VERBS) if verbs is None else set(verbs)
    for verb in VERBS:
        _add_verb(sub, verb, verb in chosen)
    return parser


USER_ERRORS: tuple[type[BaseException], ...] = (FileNotFoundError, ValueError, KeyError)
"""Exceptions a command raises for bad input (files, configs, values): reported in one line."""


def main(argv: list[str] | None = None) -> int:
    argv = list(sys.argv[1:] if argv is None else argv)
    verb = next((a for a in argv if not a.startswith("-")), None)
    parser = build_parser([verb] if verb in VERBS else [])
    args = parser.parse_args(argv)
    try:
        return int(args._run(args) or 0)
    except KeyboardInterrupt:
        print("interrupted", file=sys.stderr)
        return 130
    except SystemExit as exc:  # commands exit with a message for bad input
        if isinstance(exc.code, str):
            message = exc.code.removeprefix(f"capt {args.verb}: ")
            print(f"capt {args.verb}: error: {message}", file=sys.stderr)
            return 2
        raise
    except USER_ERRORS as exc:
        if os.environ.get("CAPT_TRACEBACK"):
            raise
        print(f"capt {args.verb}: error: {exc} (CAPT_TRACEBACK=1 shows the traceback)", file=sys.stderr)
        return 2


if __name__ == "__main__":
    sys.exit(main())
