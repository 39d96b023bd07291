"""scripts/robustness_table.py: one row per condition and method from compare_variants.py outputs."""

from __future__ import annotations

import json
from pathlib import Path

import pytest


def _mean_file(path: Path, load_script, offset: float, corruption: dict | None = None) -> Path:
    """compare_variants.py's JSON for a laptop run in which CAPT's direction error is ``offset`` deg
    above CAPT w/o DV's on every cloud."""
    cv = load_script("compare_variants")
    samples = [{"category": "laptop", "method": m, "joints": [
        {"joint_index": 0, "joint_type": "revolute", "direction_error_deg": i + off, "position_error": 0.01,
         "state_error": 3.0}]} for i in range(20) for m, off in (("capt", offset), ("capt_without_dv", 0.0))]
    summary = {m: {"laptop": {"dir_med": [9.5 + off], "pos_aed": [0.01], "state_med": [3.0],
                              "dir_flipped": [flipped]}}
               for m, off, flipped in (("capt", offset, 0.05), ("capt_without_dv", 0.0, 0.1))}
    run = {"summary": summary, "samples": samples}
    if corruption:
        run["test_corruption"] = corruption
    raw = path.with_name("run_" + path.name)
    raw.write_text(json.dumps(run))
    path.write_text(json.dumps(cv.compare([raw], draws=50)))
    return path


def test_rows_and_table(tmp_path, load_script):
    rt = load_script("robustness_table")
    clean = _mean_file(tmp_path / "mean_clean.json", load_script, -1.0)
    noisy = _mean_file(tmp_path / "mean_outliers20.json", load_script, -2.5,
                       {"jitter_m": 0.0, "outlier_fraction": 0.2})
    rows = rt.rows([clean, noisy])
    assert [(r["condition"], r["method"]) for r in rows] == [
        ("clean", "capt"), ("clean", "capt_without_dv"),
        ("outliers20", "capt"), ("outliers20", "capt_without_dv")]
    assert rows[0]["gap"] is None and rows[0]["dir_med"] == pytest.approx(8.5)
    gap = rows[3]["gap"]["dir_med"]
    assert gap["difference"] == pytest.approx(-2.5) and gap["low"] == pytest.approx(-2.5)
    assert rows[3]["corruption"] == {"jitter_m": 0.0, "outlier_fraction": 0.2}
    table = rt.markdown(rows)
    assert rows[3]["dir_flipped"] == pytest.approx(0.1)
    assert "| outliers20 | capt_without_dv | 9.50 | 0.0100 | 3.00 | 0.100 | -2.50 [-2.50, -2.50] |" in table
