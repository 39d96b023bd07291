"""scripts/attach_instance_ids.py: instance ids of the scored split written into old evaluate files."""

from __future__ import annotations

import json
from pathlib import Path

import numpy as np
import pytest

from perception.data import write_dataset
from perception.synthetic import make_box_sample


def _run(path: Path, n: int, category: str = "box_revolute") -> Path:
    samples = [{"category": category, "method": m, "joints": [], "error": i}
               for m in ("capt", "capt_plain") for i in range(n)]
    path.write_text(json.dumps({"split": "test", "summary": {}, "samples": samples}))
    return path


def test_ids_follow_the_split_order_for_every_method(tmp_path, monkeypatch, capsys, load_script):
    rng = np.random.default_rng(3)
    test = [make_box_sample(rng, 64, instance_id=iid) for iid in (11, 11, 5, 8)]
    data = write_dataset(tmp_path / "data", {"test": test}, samples_per_shard=3)
    path = _run(tmp_path / "run.json", 4)
    monkeypatch.setattr("sys.argv", ["attach_instance_ids.py", str(path), "--data", str(data)])
    load_script("attach_instance_ids").main()
    out = json.loads(path.read_text())["samples"]
    assert [(s["method"], s["error"], s["instance_id"]) for s in out] == [
        (m, i, iid) for m in ("capt", "capt_plain") for i, iid in enumerate((11, 11, 5, 8))]
    assert "3 instances" in capsys.readouterr().out


def test_the_evaluations_own_command_and_machine_are_kept(tmp_path, monkeypatch, load_script):
    rng = np.random.default_rng(4)
    data = write_dataset(tmp_path / "data", {"test": [make_box_sample(rng, 64, instance_id=2)]},
                         samples_per_shard=1)
    path = _run(tmp_path / "run.json", 1)
    run = json.loads(path.read_text())
    run.update(command="capt evaluate a.pt --data d", machine={"cpu_count": 7})
    path.write_text(json.dumps(run))
    out = tmp_path / "with_ids.json"
    monkeypatch.setattr("sys.argv", ["attach_instance_ids.py", str(path), "--data", str(data),
                                     "--out", str(out)])
    load_script("attach_instance_ids").main()
    written = json.loads(out.read_text())
    assert written["command"] == "capt evaluate a.pt --data d" and written["machine"] == {"cpu_count": 7}
    assert [s["instance_id"] for s in written["samples"]] == [2, 2]
    assert not list(tmp_path.glob("*.tmp"))  # written atomically, nothing left behind


def test_a_file_that_does_not_match_the_split_is_refused(tmp_path, load_script):
    aid = load_script("attach_instance_ids")
    with pytest.raises(ValueError, match="scored 3 clouds, the split holds 4"):
        aid.attach(json.loads(_run(tmp_path / "a.json", 3).read_text()), [1, 2, 3, 4], ["box_revolute"] * 4)
    with pytest.raises(ValueError, match="sample 0 is a laptop"):
        aid.attach(json.loads(_run(tmp_path / "b.json", 2, "laptop").read_text()), [1, 2], ["oven"] * 2)
    run = json.loads(_run(tmp_path / "c.json", 2).read_text())
    run["samples"][1]["instance_id"] = 9
    with pytest.raises(ValueError, match="already has instance_id 9"):
        aid.attach(run, [1, 2], ["box_revolute"] * 2)
