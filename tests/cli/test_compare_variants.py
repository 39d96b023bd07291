"""scripts/compare_variants.py: joint means per category, then the mean over categories."""

from __future__ import annotations

import json
from pathlib import Path

import pytest


def _write(path: Path, category: str, rows: dict) -> Path:
    path.write_text(json.dumps({"summary": {m: {category: s} for m, s in rows.items()}}))
    return path


def test_means_over_joints_then_categories(tmp_path, load_script):
    cv = load_script("compare_variants")
    a = _write(tmp_path / "a.json", "eyeglasses", {
        "capt": {"dir_med": [1.0, 3.0], "pos_aed": [0.02, 0.04], "state_med": [4.0, 6.0]},
        "capt_plain": {"dir_med": [2.0, 4.0], "pos_aed": [0.03, 0.05], "state_med": [5.0, 7.0]}})
    b = _write(tmp_path / "b.json", "drawer_cabinet", {
        "capt": {"dir_med": [6.0], "pos_aed": [None], "state_med": [0.03]},
        "capt_plain": {"dir_med": [8.0], "pos_aed": [None], "state_med": [0.05]},
        "pct_regression": {"dir_med": [9.0], "pos_aed": [None], "state_med": [0.1]}})
    result = cv.compare([a, b])
    assert result["methods"] == ["capt", "capt_plain"]  # pct_regression is missing on eyeglasses
    assert result["categories"]["eyeglasses"]["capt"]["dir_med"] == pytest.approx(2.0)
    assert result["categories"]["drawer_cabinet"]["capt"]["pos_aed"] is None  # prismatic: no position
    assert result["mean"]["capt"]["dir_med"] == pytest.approx(4.0)  # (2 + 6) / 2
    assert result["mean"]["capt"]["pos_aed"] == pytest.approx(0.03)  # eyeglasses only
    # degrees and metres are never averaged together
    assert result["mean"]["capt_plain"]["state_deg"] == pytest.approx(6.0)  # eyeglasses only
    assert result["mean"]["capt_plain"]["state_m"] == pytest.approx(0.05)  # the drawer only
    assert result["categories"]["eyeglasses"]["capt"]["state_m"] is None
    table = cv.markdown(result)
    assert "| mean | capt | 4 | 0.03 | 5 | 0.03 |" in table
    assert "| drawer_cabinet | capt | 6 | - | - | 0.03 |" in table


def test_share_of_flipped_axes_is_averaged_like_the_errors(tmp_path, load_script):
    """``dir_flipped`` (axes over 90 degrees off) is meaned over joints, runs and categories, and shown
    as the means table's last column; a file older than it leaves the cell empty."""
    cv = load_script("compare_variants")
    a = _write(tmp_path / "a.json", "eyeglasses", {
        "capt": {"dir_med": [1.0, 3.0], "pos_aed": [0.02, 0.04], "state_med": [4.0, 6.0],
                 "dir_flipped": [0.0, 0.1]}})
    b = _write(tmp_path / "b.json", "laptop", {
        "capt": {"dir_med": [2.0], "pos_aed": [0.01], "state_med": [3.0], "dir_flipped": [0.25]}})
    result = cv.compare([a, b])
    assert result["categories"]["eyeglasses"]["capt"]["dir_flipped"] == pytest.approx(0.05)
    assert result["mean"]["capt"]["dir_flipped"] == pytest.approx(0.15)
    assert "| mean | capt | 2 | 0.02 | 4 | - | 0.15 |" in cv.markdown(result)
    old = _write(tmp_path / "old.json", "oven", {
        "capt": {"dir_med": [2.0], "pos_aed": [0.01], "state_med": [3.0]}})
    assert cv.compare([old])["mean"]["capt"]["dir_flipped"] is None
    assert "| mean | capt | 2 | 0.01 | 3 | - | - |" in cv.markdown(cv.compare([old]))


def test_a_category_with_both_joint_types_and_an_all_prismatic_set(tmp_path, load_script):
    cv = load_script("compare_variants")
    mixed = _write(tmp_path / "m.json", "kitchen", {
        "capt": {"dir_med": [2.0, 4.0], "pos_aed": [0.02, None], "state_med": [6.0, 0.1]}})
    row = cv.compare([mixed])["categories"]["kitchen"]["capt"]
    assert row["state_deg"] == pytest.approx(6.0) and row["state_m"] == pytest.approx(0.1)
    drawers = _write(tmp_path / "d.json", "drawer_cabinet", {
        "capt": {"dir_med": [6.0], "pos_aed": [None], "state_med": [0.03]}})
    mean = cv.compare([drawers])["mean"]["capt"]
    assert mean["pos_aed"] is None and mean["state_deg"] is None and mean["state_m"] == pytest.approx(0.03)


def test_paired_gaps_from_per_sample_results(tmp_path, load_script):
    """With the per-sample results of `capt evaluate --json`, the reference's gap to each method comes
    with a bootstrap interval, per category and over the mean; without them there is no such table."""
    cv = load_script("compare_variants")
    samples = []
    for i in range(30):
        for method, extra in (("capt", 0.0), ("capt_plain", 2.0)):
            samples.append({"category": "laptop", "method": method, "joints": [
                {"joint_index": 0, "joint_type": "revolute", "direction_error_deg": i + extra,
                 "position_error": 0.01, "state_error": 3.0}]})
    run = {"summary": {"capt": {"laptop": {"dir_med": [14.5], "pos_aed": [0.01], "state_med": [3.0]}},
                       "capt_plain": {"laptop": {"dir_med": [16.5], "pos_aed": [0.01], "state_med": [3.0]}}},
           "samples": samples}
    path = tmp_path / "laptop.json"
    path.write_text(json.dumps(run))
    result = cv.compare([path], draws=200, seed=1)
    gap = result["paired"]["capt_plain"]["mean"]["dir_med"]
    assert gap["difference"] == pytest.approx(-2.0) and gap["high"] == pytest.approx(-2.0)
    assert result["paired"]["capt_plain"]["laptop"]["state_m"] is None
    table = cv.markdown(result)
    assert "| mean | capt - capt_plain | -2 [-2, -2] | +0 [+0, +0] | +0 [+0, +0] | - |" in table
    assert cv.compare([path], draws=0)["paired"] == {}
    summary_only = _write(tmp_path / "s.json", "laptop", {m: v["laptop"] for m, v in run["summary"].items()})
    assert cv.compare([summary_only])["paired"] == {}


def _run_file(path: Path, offsets: dict[str, float], n: int = 30) -> Path:
    """One `capt evaluate --json`-shaped laptop run: method m's direction error on cloud i is
    i + offsets[m] degrees."""
    samples = [{"category": "laptop", "method": m, "joints": [
        {"joint_index": 0, "joint_type": "revolute", "direction_error_deg": i + off, "position_error": 0.01,
         "state_error": 3.0}]} for i in range(n) for m, off in offsets.items()]
    mean = (n - 1) / 2
    summary = {m: {"laptop": {"dir_med": [mean + off], "pos_aed": [0.01], "state_med": [3.0]}}
               for m, off in offsets.items()}
    path.write_text(json.dumps({"summary": summary, "samples": samples}))
    return path


def test_two_training_runs_of_each_method_are_averaged(tmp_path, load_script):
    """Seed 0 has CAPT 1 deg worse on every cloud, seed 1 has it 3 deg better: the mean over runs is
    1 deg better, in the table and in the paired gap (whose per-cloud average makes it exact)."""
    cv = load_script("compare_variants")
    seed0 = _run_file(tmp_path / "seed0.json", {"capt": 1.0, "capt_plain": 0.0})
    seed1 = _run_file(tmp_path / "seed1.json", {"capt": 0.0, "capt_plain": 3.0})
    result = cv.compare([seed0, seed1], draws=200, seed=0)
    assert result["runs"] == {"laptop": {"capt": 2, "capt_plain": 2}}
    assert result["categories"]["laptop"]["capt"]["dir_med"] == pytest.approx(14.5 + 0.5)
    assert result["categories"]["laptop"]["capt_plain"]["dir_med"] == pytest.approx(14.5 + 1.5)
    gap = result["paired"]["capt_plain"]["mean"]["dir_med"]
    assert gap["difference"] == pytest.approx(-1.0)
    assert gap["low"] == pytest.approx(-1.0) and gap["high"] == pytest.approx(-1.0)
    assert "| laptop | capt (mean of 2 runs) | 15 |" in cv.markdown(result)


def test_runs_scored_on_different_clouds_are_refused(tmp_path, load_script):
    cv = load_script("compare_variants")
    seed0 = _run_file(tmp_path / "seed0.json", {"capt": 1.0, "capt_plain": 0.0}, n=30)
    seed1 = _run_file(tmp_path / "seed1.json", {"capt": 0.0, "capt_plain": 3.0}, n=20)
    with pytest.raises(ValueError, match="laptop capt: its runs were scored on different clouds"):
        cv.compare([seed0, seed1], draws=10)


def test_runs_scored_in_different_test_poses_are_refused(tmp_path, load_script):
    cv = load_script("compare_variants")
    world = _run_file(tmp_path / "world.json", {"capt": 1.0, "capt_plain": 0.0}, n=20)
    so3 = _run_file(tmp_path / "so3.json", {"capt": 1.0, "capt_plain": 0.0}, n=20)
    so3.write_text(json.dumps({**json.loads(so3.read_text()), "test_pose": "so3"}))
    with pytest.raises(ValueError, match="different test poses"):
        cv.compare([world, so3], draws=10)
    assert cv.compare([so3], draws=10)["test_pose"] == "so3"
    assert cv.compare([world], draws=10)["test_pose"] == "world"  # files from before --test-pose


def test_runs_scored_with_different_test_corruptions_are_refused(tmp_path, load_script):
    cv = load_script("compare_variants")
    clean = _run_file(tmp_path / "clean.json", {"capt": 1.0, "capt_plain": 0.0}, n=20)
    noisy = _run_file(tmp_path / "noisy.json", {"capt": 1.0, "capt_plain": 0.0}, n=20)
    corruption = {"jitter_m": 0.005, "outlier_fraction": 0.0}
    noisy.write_text(json.dumps({**json.loads(noisy.read_text()), "test_corruption": corruption}))
    with pytest.raises(ValueError, match="different test corruptions"):
        cv.compare([clean, noisy], draws=10)
    assert cv.compare([noisy], draws=10)["test_corruption"] == corruption
    assert cv.compare([clean], draws=10)["test_corruption"] == cv.CLEAN  # files from before the key
    filtered = _run_file(tmp_path / "filtered.json", {"capt": 1.0, "capt_plain": 0.0}, n=20)
    filtered.write_text(json.dumps({**json.loads(filtered.read_text()),
                                    "outlier_filter": {"neighbours": 8, "std_ratio": 3.0}}))
    with pytest.raises(ValueError, match="different test corruptions or outlier filters"):
        cv.compare([clean, filtered], draws=10)
    assert cv.compare([filtered], draws=10)["outlier_filter"] == {"neighbours": 8, "std_ratio": 3.0}


def test_gzip_compressed_runs_read_as_plain_ones(tmp_path, load_script):
    import gzip

    cv = load_script("compare_variants")
    plain = _run_file(tmp_path / "run.json", {"capt": 1.0, "capt_plain": 0.0}, n=20)
    packed = tmp_path / "packed.json.gz"
    packed.write_bytes(gzip.compress(plain.read_bytes()))
    a, b = cv.compare([plain], draws=50), cv.compare([packed], draws=50)
    assert a["mean"] == b["mean"] and a["paired"] == b["paired"]


def test_a_missing_input_file_is_named(tmp_path, monkeypatch, capsys, load_script):
    cv = load_script("compare_variants")
    present = _run_file(tmp_path / "seed0.json", {"capt": 1.0, "capt_plain": 0.0})
    monkeypatch.setattr("sys.argv", ["compare_variants.py", str(present), str(tmp_path / "nope.json")])
    with pytest.raises(SystemExit):
        cv.main()
    err = capsys.readouterr().err
    assert "no such capt evaluate --json file:" in err and "nope.json" in err and "seed0.json" not in err


def test_an_input_given_twice_is_refused(tmp_path, monkeypatch, capsys, load_script):
    cv = load_script("compare_variants")
    run = _run_file(tmp_path / "seed0.json", {"capt": 1.0, "capt_plain": 0.0})
    monkeypatch.setattr("sys.argv", ["compare_variants.py", str(run), str(tmp_path / "." / "seed0.json")])
    with pytest.raises(SystemExit):
        cv.main()
    assert "given twice" in capsys.readouterr().err


def test_resampling_instances_needs_their_ids_and_says_so(tmp_path, monkeypatch, capsys, load_script):
    cv = load_script("compare_variants")
    run = _run_file(tmp_path / "seed0.json", {"capt": 1.0, "capt_plain": 0.0})
    monkeypatch.setattr("sys.argv", ["compare_variants.py", str(run), "--resample", "instances"])
    with pytest.raises(SystemExit):
        cv.main()
    assert "without an instance_id" in capsys.readouterr().err
    data = json.loads(run.read_text())
    for i, s in enumerate(s for s in data["samples"] if s["method"] == "capt"):
        s["instance_id"] = i // 3
    for i, s in enumerate(s for s in data["samples"] if s["method"] == "capt_plain"):
        s["instance_id"] = i // 3
    run.write_text(json.dumps(data))
    result = cv.compare([run], draws=100, resample="instances")
    assert result["resample"] == "instances"
    assert result["paired"]["capt_plain"]["mean"]["dir_med"]["difference"] == pytest.approx(1.0)
    assert "interval over the test instances (every view of a drawn instance)" in cv.markdown(result)


def test_methods_reads_only_the_listed_rows(tmp_path, load_script):
    """A second run that also scored an ablation row: --methods leaves that row out; a method no
    file holds is named."""
    cv = load_script("compare_variants")
    seed0 = _run_file(tmp_path / "seed0.json", {"capt": 1.0, "capt_plain": 0.0})
    seed1 = _run_file(tmp_path / "seed1.json", {"capt": 0.0, "capt_plain": 3.0, "capt_without_dv": 9.0})
    everything = cv.compare([seed0, seed1], draws=0)
    assert everything["runs"]["laptop"]["capt_without_dv"] == 1
    result = cv.compare([seed0, seed1], draws=50, only=["capt", "capt_plain"])
    assert result["methods"] == ["capt", "capt_plain"] and set(result["paired"]) == {"capt_plain"}
    assert result["runs"] == {"laptop": {"capt": 2, "capt_plain": 2}}
    with pytest.raises(ValueError, match=r"no input scored the method\(s\) \['pct_regression'\]"):
        cv.compare([seed0], draws=0, only=["capt", "pct_regression"])


def test_rename_pools_checkpoints_named_after_their_paths(tmp_path, load_script):
    """Two CAPT checkpoints scored in one run carry their paths in the method name; --rename gives
    each seed's pair the same two names, so the seeds average as runs of one method, and the paired
    gap pairs the renamed rows cloud by cloud."""
    cv = load_script("compare_variants")
    seed2 = _run_file(tmp_path / "seed2.json", {"capt (runs/laptop/capt_seed2/best.pt)": 1.0,
                                                 "capt (runs/laptop/capt_motion1_seed2/best.pt)": 0.0})
    seed3 = _run_file(tmp_path / "seed3.json", {"capt (runs/laptop/capt_seed3/best.pt)": 0.0,
                                                 "capt (runs/laptop/capt_motion1_seed3/best.pt)": 3.0})
    rules = [cv.parse_rename("capt (*capt_motion1_*)=capt_motion1"), cv.parse_rename("capt (*)=capt")]
    result = cv.compare([seed2, seed3], draws=100, seed=0, reference="capt_motion1", rename=rules)
    assert result["runs"] == {"laptop": {"capt": 2, "capt_motion1": 2}}
    assert result["paired"]["capt"]["mean"]["dir_med"]["difference"] == pytest.approx(1.0)
    assert result["rename"] == [["capt (*capt_motion1_*)", "capt_motion1"], ["capt (*)", "capt"]]
    clash = r"seed2.json: --rename gives two of its methods the name\(s\) \['capt'\]"
    with pytest.raises(ValueError, match=clash):
        cv.compare([seed2], draws=0, rename=[("capt (*)", "capt")])
    assert cv.parse_rename("a=b=c") == ("a=b", "c")
    with pytest.raises(ValueError, match="PATTERN=NAME"):
        cv.parse_rename("capt")


def test_main_writes_markdown_and_json_with_its_command(tmp_path, monkeypatch, load_script):
    cv = load_script("compare_variants")
    a = _write(tmp_path / "a.json", "oven", {
        "capt": {"dir_med": [1.0], "pos_aed": [0.02], "state_med": [4.0]},
        "capt_plain": {"dir_med": [2.0], "pos_aed": [0.03], "state_med": [5.0]}})
    md, js = tmp_path / "out" / "cmp.md", tmp_path / "out" / "cmp.json"
    monkeypatch.setattr("sys.argv", ["compare_variants.py", str(a), "--draws", "0", "--markdown", str(md),
                                     "--json", str(js)])
    cv.main()
    command = f".venv/bin/python scripts/compare_variants.py {a} --draws 0 --markdown {md} --json {js}"
    assert md.read_text().startswith(f"`{command}`\n\n| category | method |")
    written = json.loads(js.read_text())
    assert written["command"] == command and "cpu_count" in written["machine"]
    assert written["categories"]["oven"]["capt_plain"]["dir_med"] == pytest.approx(2.0)
    # an argument with spaces is quoted, so the recorded command pastes back into a shell
    monkeypatch.setattr("sys.argv", ["compare_variants.py", str(a), "--draws", "0", "--rename",
                                     "capt (*)=capt", "--json", str(js)])
    cv.main()
    assert json.loads(js.read_text())["command"].endswith(f"--rename 'capt (*)=capt' --json {js}")
