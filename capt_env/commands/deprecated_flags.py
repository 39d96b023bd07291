"""Old flag spellings kept for one release: each still works as a hidden alias of its canonical flag
and prints one line ``capt VERB: --old is deprecated; use --new`` to stderr.

One name per concept across the verbs: ``--categories`` (a list of categories; ``--category`` only
where exactly one is taken), ``--first-seed`` (the first episode's seed; ``--seed`` is a config's
seed), ``--episodes`` (episodes, i.e. seeded resets, per category; ``capt bench --resets`` counts
timed resets, no episode is played), ``--checkpoint`` (a CAPT
checkpoint; ``--init-checkpoint`` for the one a training run starts from), ``--model`` (a PPO
model .zip), ``--perception`` (the perception source). ``capt_env.cli`` applies ``DEPRECATED_FLAGS``
to each verb's parser; drop an entry to retire its old spelling.
"""

from __future__ import annotations

import argparse
import sys

# verb -> {old spelling: canonical flag}
DEPRECATED_FLAGS: dict[str, dict[str, str]] = {
    "demo": {"--category": "--categories", "--seed": "--first-seed"},
    "bench": {"--seed": "--first-seed"},
    "estimate-errors": {"--resets": "--episodes"},
    "train": {"--init-from": "--init-checkpoint"},
}


class _DeprecatedAlias(argparse.Action):
    """Warns once per use, then acts exactly as the canonical flag's action."""

    def __init__(self, option_strings: list[str], dest: str, canonical: argparse.Action, **kwargs) -> None:
        super().__init__(option_strings, dest, **kwargs)
        self.canonical = canonical

    def __call__(self, parser: argparse.ArgumentParser, namespace: argparse.Namespace, values,
                 option_string: str | None = None) -> None:
        new = self.canonical.option_strings[0]
        print(f"{parser.prog}: {option_string} is deprecated; use {new}", file=sys.stderr)
        self.canonical(parser, namespace, values, new)


def add_deprecated_alias(parser: argparse.ArgumentParser, old: str, new: str) -> None:
    """Make ``old`` a hidden alias of the option ``new`` (same dest, nargs, type and choices)."""
    actions = parser._option_string_actions  # argparse's option-string -> action map
    if new not in actions:
        raise ValueError(f"{parser.prog} has no {new}")
    if old in actions:
        raise ValueError(f"{parser.prog} declares both {old} and {new}")
    canonical = actions[new]
    parser.add_argument(old, action=_DeprecatedAlias, canonical=canonical, dest=argparse.SUPPRESS,
                        nargs=canonical.nargs, type=canonical.type, choices=canonical.choices,
                        default=argparse.SUPPRESS, help=argparse.SUPPRESS)


def apply_deprecated_flags(parser: argparse.ArgumentParser, verb: str) -> None:
    """Add the hidden aliases of ``verb``'s old spellings to its parser."""
    for old, new in DEPRECATED_FLAGS.get(verb, {}).items():
        add_deprecated_alias(parser, old, new)
