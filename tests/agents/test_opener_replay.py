"""The scripted opener's actions are a contract: the episodes recorded by
``scripts/record_opener_actions.py`` (ground-truth perception, the five procedural categories on seeds
300-303 and the Meta-World corpus on seeds 100-102, ``tests/data/opener_actions.npz``) come out action
for action the same (``np.array_equal``), with the same phase log.

Re-record only on purpose, when a change is meant to change what the opener does."""

from __future__ import annotations

import importlib.util
import json
from pathlib import Path

import numpy as np
import pytest

from agents.scripted import ScriptedOpener

ROOT = Path(__file__).resolve().parents[2]
RECORDING = ROOT / "tests" / "data" / "opener_actions.npz"


def _recorder():
    spec = importlib.util.spec_from_file_location("record_opener_actions",
                                                  ROOT / "scripts" / "record_opener_actions.py")
    assert spec is not None and spec.loader is not None
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module


def _episodes() -> list[tuple[str, int]]:
    with np.load(RECORDING) as data:
        keys = sorted({tuple(k.split("/")[:2]) for k in data.files})
    return [(name, int(seed)) for name, seed in keys]


def _recorded(name: str, seed: int) -> tuple[np.ndarray, np.ndarray, list]:
    with np.load(RECORDING) as data:
        return (data[f"{name}/{seed}/obs"], data[f"{name}/{seed}/actions"],
                json.loads(str(data[f"{name}/{seed}/phase_log"])))


def test_recorded_observations_give_the_recorded_actions() -> None:
    """Every recorded episode, fed its observations without the simulator (the opener's actions
    depend on nothing else, so the same actions on the same observations replay the episode)."""
    episodes = _episodes()
    assert len(episodes) == 35
    for name, seed in episodes:
        obs, actions, log = _recorded(name, seed)
        opener = ScriptedOpener()
        opener.reset()
        for t, o in enumerate(obs):
            action = np.asarray(opener.act(o, {}), dtype=np.float32)
            assert np.array_equal(action, actions[t]), f"{name} seed {seed} step {t + 1}: {action}"
        assert json.loads(json.dumps(opener.phase_log)) == log, f"{name} seed {seed}: phase log"


def _replay_in_simulator(name: str, seed: int) -> None:
    recorder = _recorder()
    obs, actions, log = _recorded(name, seed)
    env = recorder.make_episode_env(name)
    try:
        opener = ScriptedOpener()
        seen, done = recorder.play(env, opener, seed)
    finally:
        env.close()
    assert np.array_equal(seen, obs), f"{name} seed {seed}: observations differ"
    assert np.array_equal(done, actions), f"{name} seed {seed}: actions differ"
    assert json.loads(json.dumps(opener.phase_log)) == log


@pytest.mark.parametrize(("name", "seed"), [("oven", 300), ("mw_laptop", 100)])
def test_episodes_replay_in_the_simulator(name: str, seed: int) -> None:
    """A door that falls open (re-grasp, wait while it falls) and a lid lifted from below, in closed loop."""
    _replay_in_simulator(name, seed)


@pytest.mark.slow
def test_every_recorded_episode_replays_in_the_simulator() -> None:
    for name, seed in _episodes():
        _replay_in_simulator(name, seed)
