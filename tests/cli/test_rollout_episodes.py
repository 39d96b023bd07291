"""``capt rollout``: finished episodes survive an interruption (``--episode-log``) and are not played
again; worker processes (``--workers``) play the same episodes."""

from __future__ import annotations

import json
from pathlib import Path

import pytest

from capt_env.cli import main
from capt_env.commands.episode_log import EpisodeLog

RUN = {"category": "oven", "perception": "capt", "task": {"cameras": ({"name": "left"},)}}


def _episode(seed: int, success: bool = True) -> dict:
    return {"seed": seed, "instance_id": 7, "success": success, "open_fraction": 0.9, "steps": 120,
            "phase": "done"}


def test_episodes_are_read_back_only_for_the_same_run(tmp_path: Path) -> None:
    path = tmp_path / "episodes.jsonl"
    log = EpisodeLog(path, RUN)
    assert len(log) == 0 and log.recorded(0) is None
    log.append(_episode(0))
    log.append(_episode(3, success=False))
    again = EpisodeLog(path, RUN)  # the tuple in the task compares equal to the list read back
    assert len(again) == 2 and again.recorded(3) == _episode(3, success=False)
    other = EpisodeLog(path, {**RUN, "perception": "oracle"})
    assert len(other) == 0
    other.append(_episode(3))
    assert EpisodeLog(path, RUN).recorded(3)["success"] is False
    assert len(path.read_text().splitlines()) == 3


def test_a_line_cut_short_by_a_crash_is_ignored_and_overwritten(tmp_path: Path) -> None:
    path = tmp_path / "episodes.jsonl"
    EpisodeLog(path, RUN).append(_episode(0))
    with open(path, "a") as fh:
        fh.write('{"run": {"category": "oven", "perc')  # killed mid-line
    log = EpisodeLog(path, RUN)
    assert len(log) == 1
    log.append(_episode(1))
    lines = [json.loads(line) for line in path.read_text().splitlines()]
    assert [line["episode"]["seed"] for line in lines] == [0, 1]


def test_a_file_of_something_else_is_refused(tmp_path: Path) -> None:
    path = tmp_path / "notes.jsonl"
    path.write_text('{"loss": 0.3}\n')
    with pytest.raises(ValueError, match="not an episode record"):
        EpisodeLog(path, RUN)


def test_rollout_resumes_from_its_episode_log(tmp_path: Path) -> None:
    log, out = tmp_path / "episodes.jsonl", tmp_path / "rollout.json"
    args = ["rollout", "--categories", "cabinet_door", "--max-steps", "3", "--episode-log", str(log)]
    assert main([*args, "--episodes", "2"]) == 0
    first = [json.loads(line)["episode"] for line in log.read_text().splitlines()]
    assert [e["seed"] for e in first] == [0, 1] and all(e["steps"] == 3 for e in first)
    assert main([*args, "--episodes", "3", "--json", str(out)]) == 0
    lines = log.read_text().splitlines()
    assert len(lines) == 3  # seeds 0 and 1 were read back, only seed 2 was played
    episodes = json.loads(out.read_text())["results"][0]["episodes"]
    assert episodes[:2] == first and episodes[2]["seed"] == 2
    assert main([*args, "--episodes", "1", "--max-steps", "4"]) == 0  # another run: played anew
    assert json.loads(log.read_text().splitlines()[-1])["episode"]["steps"] == 4


def test_worker_processes_play_the_same_episodes(tmp_path: Path) -> None:
    out = {n: tmp_path / f"rollout_{n}.json" for n in (1, 2)}
    for workers, path in out.items():
        assert main(["rollout", "--categories", "laptop", "--episodes", "3", "--max-steps", "25",
                     "--workers", str(workers), "--json", str(path)]) == 0
    one, two = (json.loads(out[n].read_text()) for n in (1, 2))
    assert two["workers"] == 2 and [e["seed"] for e in two["results"][0]["episodes"]] == [0, 1, 2]
    assert one["results"][0]["episodes"] == two["results"][0]["episodes"]
    assert len({e["open_fraction"] for e in one["results"][0]["episodes"]}) > 1  # the seeds differ


def test_bad_worker_and_episode_counts_are_named(capsys: pytest.CaptureFixture[str]) -> None:
    assert main(["rollout", "--workers", "0"]) == 2
    assert "--workers" in capsys.readouterr().err
    assert main(["rollout", "--episodes", "0"]) == 2
    assert "--episodes" in capsys.readouterr().err


def test_failed_episodes_are_counted_by_the_cause_in_their_phase_log(tmp_path: Path) -> None:
    out, table = tmp_path / "rollout.json", tmp_path / "rollout.md"
    # three steps: the hand is still on its way to the pre-grasp when the episode ends
    assert main(["rollout", "--categories", "cabinet_door", "--episodes", "1", "--max-steps", "3",
                 "--json", str(out), "--markdown", str(table)]) == 0
    row = json.loads(out.read_text())["results"][0]
    episode = row["episodes"][0]
    assert episode["phase_log"] == [{"step": 0, "phase": "pregrasp", "why": "start"}]
    assert episode["cause"] == "no grasp found" and row["failure_causes"]["no grasp found"] == 1
    header, _, line = table.read_text().splitlines()
    assert header.endswith("| failures by cause |") and line.endswith("| no grasp found 1 |")
