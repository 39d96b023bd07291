"""The scripts that train away from the full datasets: packed clouds keep object points only, at the
precision and size asked for, and still train; a budgeted run re-plans its epochs after one timed epoch."""

from __future__ import annotations

import json
import sys
from collections.abc import Callable
from pathlib import Path
from types import ModuleType

import numpy as np
import yaml

from capt_common.typed_yaml import to_dict
from perception.config import CaptConfig, TrainConfig
from perception.data import load_split, write_dataset
from perception.training import epoch_seconds

from .helpers import make_samples, tiny_model_config


def _dataset(tmp_path: Path) -> Path:
    splits = {"train": make_samples(12, seed=1), "val": make_samples(4, seed=2)}
    return write_dataset(tmp_path / "data", splits, samples_per_shard=8)


def test_packed_clouds_keep_object_points_at_half_precision(
        tmp_path: Path, load_script: Callable[[str], ModuleType]) -> None:
    pack = load_script("pack_training_clouds")
    src = _dataset(tmp_path)
    full = load_split(src, "train")
    packed = pack.pack_split(full, 64, limit=5, rng=np.random.default_rng(0))
    assert packed["points"].shape == (5, 64, 3) and packed["points"].dtype == np.float16
    assert packed["part_labels"].dtype == np.int8 and (packed["part_labels"] >= 0).all()
    for i in range(5):  # each packed point is one of the sample's own object points, label and all
        obj = full["part_labels"][i] >= 0
        pts, labels = full["points"][i][obj], full["part_labels"][i][obj]
        d = np.linalg.norm(pts[None] - packed["points"][i].astype(np.float64)[:, None], axis=-1)
        nearest = d.argmin(axis=1)
        assert d.min(axis=1).max() < 2e-3
        np.testing.assert_array_equal(labels[nearest], packed["part_labels"][i])
    np.testing.assert_array_equal(packed["joint_dirs"], full["joint_dirs"][:5])


def test_a_budgeted_run_times_one_epoch_then_plans_the_rest(
        tmp_path: Path, load_script: Callable[[str], ModuleType], monkeypatch) -> None:
    script = load_script("train_within_budget")
    config = TrainConfig(model=CaptConfig(model=tiny_model_config("capt")), batch_size=8, device="cpu")
    config_path = tmp_path / "train.yaml"
    config_path.write_text(yaml.safe_dump(to_dict(config)))
    out = tmp_path / "run"
    monkeypatch.setattr(script, "RESERVE_S", 0.0)
    monkeypatch.setattr(sys, "argv", ["train_within_budget", "--config", str(config_path), "--data",
                                      str(_dataset(tmp_path)), "--out", str(out), "--seconds", "1e6",
                                      "--max-epochs", "3", "--device", "cpu"])
    script.main()
    report = json.loads((out / "train.json").read_text())
    assert report["epochs_run"] == 3 == len(epoch_seconds(out / "log.csv"))  # capped by --max-epochs
    assert (out / "best.pt").exists() and (out / "last.pt").exists()
    # no time left after the timed epoch: the run ends there, its schedule re-planned to that epoch
    short = tmp_path / "short"
    argv = [a if a != str(out) else str(short) for a in sys.argv]
    monkeypatch.setattr(sys, "argv", [a if a != "1e6" else "0" for a in argv])
    script.main()
    assert json.loads((short / "train.json").read_text())["epochs_run"] == 1
