"""One name per concept across the ``capt`` verbs: the canonical flags are the ones in help, and each
old spelling still parses to the same value for one release, with one deprecation line on stderr."""

from __future__ import annotations

import re

import pytest

from capt_env.cli import VERBS, build_parser
from capt_env.commands.deprecated_flags import DEPRECATED_FLAGS

# what a verb needs besides the flag under test, and a value for each canonical flag
REQUIRED = {"train": ["--data", "d", "--out", "o"]}
VALUES = {"--categories": ["oven"], "--first-seed": ["3"], "--episodes": ["2"],
          "--init-checkpoint": ["x.pt"]}
# old spellings that stay canonical in other verbs, with another meaning there: a config's seed (not
# the first episode's), exactly one category (not a list), a number of timed resets (no episode is played)
OTHER_MEANING = {"--seed": {"train", "generate"}, "--category": {"bench", "generate"}, "--resets": {"bench"}}
OLD = {old for renames in DEPRECATED_FLAGS.values() for old in renames}


def _help(verb: str) -> str:
    parser = build_parser([verb])
    sub = next(a for a in parser._actions if a.dest == "verb")
    return sub.choices[verb].format_help()


def _options(text: str) -> set[str]:
    return set(re.findall(r"(?<![\w-])--[a-z][a-z-]*", text))


CASES = [(verb, old, new) for verb, renames in DEPRECATED_FLAGS.items() for old, new in renames.items()]


@pytest.mark.parametrize(("verb", "old", "new"), CASES, ids=[f"{v}{o}" for v, o, _ in CASES])
def test_old_spelling_parses_to_the_same_value_and_warns(verb: str, old: str, new: str, capsys) -> None:
    argv = [verb, *REQUIRED.get(verb, [])]
    canonical = vars(build_parser([verb]).parse_args([*argv, new, *VALUES[new]]))
    assert capsys.readouterr().err == ""
    deprecated = vars(build_parser([verb]).parse_args([*argv, old, *VALUES[new]]))
    assert deprecated == canonical
    assert capsys.readouterr().err.splitlines() == [f"capt {verb}: {old} is deprecated; use {new}"]


@pytest.mark.parametrize("verb", list(VERBS))
def test_help_lists_only_canonical_names(verb: str) -> None:
    options = _options(_help(verb))
    assert options >= set(DEPRECATED_FLAGS.get(verb, {}).values())
    retired = {old for old in OLD if verb not in OTHER_MEANING.get(old, set())}
    assert options.isdisjoint(retired), options & retired


def test_shared_concepts_have_one_name() -> None:
    """Flags that several verbs take are spelled the same in each."""
    options = {verb: _options(_help(verb)) for verb in VERBS}
    for verb in ("demo", "rollout", "estimate-errors", "noise-sweep"):
        assert {"--categories", "--episodes", "--first-seed"} <= options[verb], verb
    for verb in ("demo", "rollout", "estimate-errors"):
        assert "--checkpoint" in options[verb], verb
    for verb in ("rollout", "noise-sweep"):
        assert {"--model", "--policy", "--every-k-steps"} <= options[verb], verb
    assert not any({"--source", "--weights", "--resets-per-category"} & o for o in options.values())
