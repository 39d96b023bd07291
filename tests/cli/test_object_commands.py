"""Every evaluation command takes user files: rollout, generate, inspect-object, --objects YAML."""

from __future__ import annotations

import json
from pathlib import Path

import numpy as np
import pytest

from capt_env.cli import main
from capt_env.objects.registry import make_object
from capt_env.objects.user_files import spec_to_urdf


@pytest.fixture(scope="module")
def drawer_urdf(tmp_path_factory: pytest.TempPathFactory) -> Path:
    path = tmp_path_factory.mktemp("files") / "small_drawer.urdf"
    path.write_text(spec_to_urdf(make_object("drawer_cabinet", 3)))
    return path


def test_rollout_takes_an_object_file_and_names_it_by_its_stem(drawer_urdf: Path, tmp_path: Path,
                                                               capsys: pytest.CaptureFixture[str]) -> None:
    out = tmp_path / "rollout.json"
    assert main(["rollout", "--categories", "--object", str(drawer_urdf), "--joint", "drawer_1_slide",
                 "--episodes", "1", "--max-steps", "3", "--json", str(out)]) == 0
    assert "| small_drawer | oracle |" in capsys.readouterr().out
    row = json.loads(out.read_text())["results"][0]
    assert row["object"] == "small_drawer" and row["category"] is None
    assert row["task"]["object"] == str(drawer_urdf) and row["task"]["joint"] == "drawer_1_slide"
    assert len(row["episodes"]) == 1 and row["episodes"][0]["instance_id"] == -1


def test_generate_renders_labelled_clouds_of_an_object_file(drawer_urdf: Path, tmp_path: Path) -> None:
    out = tmp_path / "data"
    assert main(["generate", "--object", str(drawer_urdf), "--out", str(out), "--train", "0", "--val", "0",
                 "--test", "2", "--workers", "1"]) == 0
    manifest = json.loads((out / "manifest.json").read_text())
    assert manifest["config"]["object"]["object"] == str(drawer_urdf)
    shards = sorted(out.rglob("*.npz"))
    data = np.load(shards[0])
    assert str(data["category"][0]) == "small_drawer"
    assert data["points"].shape[1:] == (2048, 3)
    assert set(np.unique(data["part_labels"])) <= {0, 1, 2} and (data["part_labels"] > 0).any()
    states, limits = data["joint_states"][:, :2], data["joint_limits"][:, :2]
    assert ((states >= -1e-5) & (states <= limits[..., 1] + 1e-5)).all()  # 0 closed, growing open


def test_objects_yaml_lists_files_with_their_options(drawer_urdf: Path, tmp_path: Path) -> None:
    from capt_env.commands.object_targets import load_objects_yaml

    listing = tmp_path / "objects.yaml"
    listing.write_text(f"objects:\n  - path: {drawer_urdf}\n    name: top_drawer\n    like: drawer_cabinet\n"
                       "    task: {joint: drawer_1_slide, closed: lower}\n")
    (target,) = load_objects_yaml(listing)
    assert target.label == "top_drawer" and target.model_category() == "drawer_cabinet"
    assert target.task == {"object": str(drawer_urdf), "joint": "drawer_1_slide", "closed": "lower"}
    listing.write_text(f"objects:\n  - path: {drawer_urdf}\n    task: {{category: oven}}\n")
    with pytest.raises(SystemExit, match=r"objects\[0\].*category"):
        load_objects_yaml(listing)


def test_inspect_object_reports_joints_reach_and_writes_a_picture(drawer_urdf: Path, tmp_path: Path,
                                                                  capsys: pytest.CaptureFixture[str]) -> None:
    png, out = tmp_path / "look.png", tmp_path / "inspect.json"
    assert main(["inspect-object", str(drawer_urdf), "--joint", "drawer_1_slide", "--png", str(png),
                 "--json", str(out)]) == 0
    text = capsys.readouterr().out
    assert "drawer_1_slide" in text and "<- target" in text and "in reach" in text
    report = json.loads(out.read_text())
    assert png.is_file() and png.stat().st_size > 5000
    assert report["grasp_from"] == "geometry" and report["reach"]["ok"]
    # the procedural drawer's bar stands a few cm off its front, within CAPT's handle search
    assert 0.01 < report["grasp_standoff_m"] < 0.08 and "handle: its grip stands" in text
    assert "beyond the band" not in text
    assert [j["closed_at"] for j in report["joints"]] == ["lower", "lower"]
    assert abs(report["front_azimuth_rad"]) == pytest.approx(np.pi)  # procedural fronts face -x


def test_demo_estimates_an_object_file(drawer_urdf: Path, tmp_path: Path,
                                       capsys: pytest.CaptureFixture[str]) -> None:
    out = tmp_path / "demo.json"
    assert main(["demo", "--object", str(drawer_urdf), "--joint", "drawer_1_slide", "--no-policy",
                 "--out", str(tmp_path / "demo"), "--json", str(out)]) == 0
    assert "small_drawer_episode0 (user file)" in capsys.readouterr().out
    (row,) = json.loads(out.read_text())["episodes"]
    assert row["object"] == "small_drawer" and Path(row["png"]).is_file()


@pytest.mark.parametrize(("category", "iid", "expected"), [
    ("drawer_cabinet", 3, "drawer_cabinet"),   # slides out of its front
    ("sliding_panel", 0, "sliding_panel"),     # a sash sliding up across its front
    ("sliding_panel", 20, "sliding_panel"),    # one sliding sideways
    ("cabinet_door", 1, "cabinet_door"),       # revolute
])
def test_a_file_without_like_gets_the_model_of_how_its_part_moves(category: str, iid: int, expected: str,
                                                                   tmp_path: Path) -> None:
    from capt_env.commands.object_targets import ObjectTarget

    path = tmp_path / f"{category}.urdf"
    path.write_text(spec_to_urdf(make_object(category, iid)))
    assert ObjectTarget(label="file", task={"object": str(path)}).model_category() == expected


def test_inspect_object_says_which_handle_search_finds_a_grip() -> None:
    from capt_env.commands.inspect_object import handle_search_note

    assert handle_search_note(0.05) == ""  # within the first band
    assert "found only when nothing stands in that band" in handle_search_note(0.10)  # a bar on long posts
    assert "may fall back" in handle_search_note(0.15)  # beyond both


@pytest.mark.parametrize("verb", ["rollout", "estimate-errors"])
def test_user_files_alone_evaluate_no_default_category(verb: str, drawer_urdf: Path) -> None:
    from capt_env.cli import build_parser
    from capt_env.commands.object_targets import object_targets

    parser = build_parser()
    alone = object_targets(parser.parse_args([verb, "--object", str(drawer_urdf)]))
    assert [t.label for t in alone] == ["small_drawer"]
    beside = object_targets(parser.parse_args([verb, "--categories", "laptop", "--object", str(drawer_urdf)]))
    assert [t.label for t in beside] == ["laptop", "small_drawer"]
    assert [t.label for t in object_targets(parser.parse_args([verb]))] == ["cabinet_door"]
