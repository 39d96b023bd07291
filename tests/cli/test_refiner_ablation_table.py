"""scripts/refiner_ablation_table.py: one table per object from ``capt estimate-errors --without-refiner``
JSON, each row's change against full ``capt`` and how often the left-out refiner fired."""

from __future__ import annotations

import json
from collections.abc import Callable
from pathlib import Path
from types import ModuleType


def _row(source: str, left_out: str | None, direction: float, fired: list[list[str]]) -> dict:
    refiners = "none" if source == "capt_raw" else "all" if left_out is None else f"all but {left_out}"
    return {"object": "cabinet_door", "perception": source, "without_refiner": left_out, "refiners": refiners,
            "joint_type": "revolute", "direction_deg_mean": direction, "direction_deg_median": direction,
            "sign_right": 1.0, "line_m_mean": 0.02, "line_m_median": 0.02, "state_error_mean": 0.1,
            "grasp_m_mean": 0.03, "per_reset": [{"fired": f} for f in fired]}


def test_table_has_the_change_against_capt_and_the_fire_rate(
        tmp_path: Path, load_script: Callable[[str], ModuleType]) -> None:
    script = load_script("refiner_ablation_table")
    fired = [["handle", "opening_sign"], ["handle"], [], ["handle"]]
    data = {"command": "capt estimate-errors --without-refiner all", "seeds": [0, 1, 2, 3],
            "results": [_row("capt_raw", None, 40.0, [[]] * 4), _row("capt", None, 1.0, fired),
                        _row("capt", "handle", 90.0, [[]] * 4), _row("capt", "opening_sign", 1.0, fired)]}
    lines = script.object_table(data["results"])
    assert lines[2].startswith("| capt_raw | none | - | 40.0 (+39.0) | 40.0 |")
    assert lines[3].startswith("| capt | all | - | 1.0 | 1.0 |")
    assert lines[4].startswith("| capt | all but handle | 0.75 | 90.0 (+89.0) |")
    assert lines[5].startswith("| capt | all but opening_sign | 0.25 | 1.0 | 1.0 |")
    assert "state (deg, mean)" in lines[0] and "| 5.7 |" in lines[3]  # 0.1 rad
    path, out = tmp_path / "ablation.json", tmp_path / "ablation.md"
    path.write_text(json.dumps(data))
    script.main([str(path), "--out", str(out)])
    assert out.read_text().startswith("`capt estimate-errors --without-refiner all`")
