"""``capt noise-sweep`` and ``--noise``: the swept error reaches the noisy oracle in the right unit,
every other error is zero, bad values are refused naming them, and a run records what it swept."""

from __future__ import annotations

import json
import math
from pathlib import Path

import pytest

from capt_env.cli import main
from capt_env.commands.episode_runner import EpisodeJob
from capt_env.commands.noise_overrides import noise_overrides
from capt_env.commands.noise_sweep import sweep_noise


def test_a_sweep_point_sets_only_the_swept_error_in_the_configs_unit() -> None:
    noise = sweep_noise("direction_deg", 10.0, "fixed_offset", {})
    assert noise["direction_rad"] == pytest.approx(math.radians(10.0))
    assert noise["model"] == "fixed_offset"
    assert {k: v for k, v in noise.items() if k not in ("direction_rad", "model")} == {
        "pivot_m": 0.0, "state": 0.0, "grasp_m": 0.0, "grasp_outward_m": 0.0}
    held = sweep_noise("pivot_m", 0.05, "gaussian", {"direction_rad": 0.02})
    assert held["pivot_m"] == 0.05 and held["direction_rad"] == 0.02 and held["model"] == "gaussian"
    with pytest.raises(SystemExit, match="direction_rad"):
        sweep_noise("direction_deg", 5.0, "fixed_offset", {"direction_rad": 0.1})


def test_noise_overrides_parse_and_name_what_is_wrong() -> None:
    parsed = noise_overrides(["pivot_m=0.02", "model=fixed_offset"])
    assert parsed == {"pivot_m": 0.02, "model": "fixed_offset"}
    for bad, named in [(["pivot=0.1"], "pivot"), (["pivot_m=abc"], "pivot_m"), (["pivot_m"], "KEY=VALUE"),
                       (["grasp_m=-0.01"], "grasp_m"), (["model=uniform"], "model")]:
        with pytest.raises(SystemExit, match=named):
            noise_overrides(bad)


def test_rollout_refuses_noise_without_the_noisy_oracle(capsys: pytest.CaptureFixture[str]) -> None:
    assert main(["rollout", "--perception", "oracle", "--noise", "pivot_m=0.01", "--episodes", "1"]) == 2
    assert "noisy_oracle" in capsys.readouterr().err


def test_the_noise_is_part_of_an_evaluations_identity() -> None:
    def job(noise: dict) -> EpisodeJob:
        wrapper = {"source": "noisy_oracle", "every_k_steps": 5, "noise": noise}
        return EpisodeJob("laptop", wrapper, {}, "state", "scripted", None, None, 200)

    # the defaults written out or left implicit are the same run; another size is another run
    assert job({}).identity() == job({"model": "gaussian"}).identity()
    assert job({}).identity() != job({"direction_rad": 0.3}).identity()


def test_noise_sweep_plays_every_value_on_the_same_seeds(tmp_path: Path,
                                                        capsys: pytest.CaptureFixture[str]) -> None:
    out, table = tmp_path / "sweep.json", tmp_path / "sweep.md"
    assert main(["noise-sweep", "--categories", "cabinet_door", "--parameter", "direction_deg",
                 "--values", "0", "30", "--episodes", "1", "--first-seed", "4", "--max-steps", "3",
                 "--json", str(out), "--markdown", str(table)]) == 0
    report = json.loads(out.read_text())
    assert report["parameter"] == "direction_deg" and report["unit"] == "deg" and report["seeds"] == [4]
    rows = report["results"]
    assert [r["value"] for r in rows] == [0.0, 30.0]
    assert rows[1]["noise"]["direction_rad"] == pytest.approx(math.radians(30.0))
    assert rows[1]["noise"]["model"] == "fixed_offset" and rows[1]["noise"]["pivot_m"] == 0.0
    assert all(r["episodes"][0]["seed"] == 4 and r["episodes"][0]["steps"] <= 3 for r in rows)
    assert "| cabinet_door | 30 |" in table.read_text()
    assert main(["noise-sweep", "--parameter", "pivot_m", "--values", "-0.01"]) == 2
    assert "values" in capsys.readouterr().err


def test_rollout_records_the_noise_it_ran_with(tmp_path: Path) -> None:
    out = tmp_path / "rollout.json"
    assert main(["rollout", "--categories", "laptop", "--perception", "noisy_oracle", "--noise",
                 "model=fixed_offset", "direction_rad=0.1", "--episodes", "1", "--max-steps", "3",
                 "--json", str(out)]) == 0
    noise = json.loads(out.read_text())["noise"]
    assert noise["model"] == "fixed_offset" and noise["direction_rad"] == 0.1
    assert noise["pivot_m"] == 0.01  # unset fields are the defaults, written out
