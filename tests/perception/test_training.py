"""Training loop (checkpoints, resume, CSV log, voting window) and evaluation on a tiny synthetic set."""

from __future__ import annotations

import csv
from unittest import mock

import pytest

from perception.checkpoint import load_checkpoint
from perception.config import CaptConfig, TrainConfig
from perception.corruption import Corruption
from perception.data import write_dataset
from perception.evaluation import evaluate
from perception.inference import ArticulationEstimator
from perception.outlier_filter import OutlierFilter
from perception.training import epoch_seconds, train

from .helpers import make_samples, tiny_model_config


@pytest.fixture
def data_dir(tmp_path):
    splits = {"train": make_samples(16, seed=1), "val": make_samples(4, seed=2),
              "test": make_samples(4, seed=3)}
    return write_dataset(tmp_path / "data", splits, samples_per_shard=8)


def _cfg(variant: str, epochs: int) -> TrainConfig:
    return TrainConfig(model=CaptConfig(model=tiny_model_config(variant)), epochs=epochs, batch_size=8,
                       progress=False, device="cpu")


def test_train_resume_and_evaluate(tmp_path, data_dir):
    out = tmp_path / "run"
    first = train(_cfg("capt", 3), data_dir, out, stop_after=2)  # interrupted after 2 of 3 epochs
    ckpt = load_checkpoint(first.last_path)
    assert first.epochs_run == 2 and ckpt.extra["epoch"] == 1 and ckpt.voting_window == first.voting_window
    assert load_checkpoint(first.best_path).voting_window == first.voting_window
    assert first.voting_window[0] < first.voting_window[1]
    resumed = train(_cfg("capt", 3), data_dir, out)
    rows = list(csv.DictReader(open(resumed.log_path)))
    assert [r["epoch"] for r in rows] == ["0", "1", "2"]
    assert float(rows[0]["train_total"]) > 0 and float(rows[0]["val_total"]) > 0
    seconds = epoch_seconds(resumed.log_path)  # what `capt train --json` reports, resumed epochs too
    assert len(seconds) == 3 and all(s > 0 for s in seconds)
    assert load_checkpoint(resumed.last_path).extra["epoch"] == 2

    # Same seed, uninterrupted run: identical weights to the interrupted-then-resumed one.
    straight = train(_cfg("capt", 3), data_dir, tmp_path / "straight", resume=False)
    a, b = load_checkpoint(resumed.last_path).state_dict, load_checkpoint(straight.last_path).state_dict
    assert all((a[k].float() - b[k].float()).abs().max() < 1e-5 for k in a)

    plain = train(_cfg("pct_regression", 1), data_dir, tmp_path / "pct")
    spy = mock.patch.object(ArticulationEstimator, "predict", autospec=True,
                            side_effect=ArticulationEstimator.predict)
    with spy as calls:
        ev = evaluate([resumed.best_path, plain.best_path], data_dir, "test", timing_clouds=5, progress=False)
    assert calls.call_count == 2 * (3 + 4 + 1)  # per checkpoint: 3 warm-up, 4 scored and timed, 1 more timed
    assert len(ev.results) == 8 and set(ev.median_ms) == {"capt", "pct_regression"}
    assert all(r.joints and 0 <= r.joints[0].direction_error_deg <= 180 for r in ev.results)
    assert all(r.pa is not None for r in ev.results if r.method == "capt")
    assert "| box_revolute | capt |" in ev.table and "| box_revolute | pct_regression | - | - |" in ev.table

    # the paper's "CAPT w/o DV": the CAPT checkpoint scored again with the coarse vote only
    ablation = evaluate([resumed.best_path, plain.best_path], data_dir, "test", timing_clouds=3,
                        progress=False, without_double_voting=True)
    rows = {m: [r for r in ablation.results if r.method == m] for m in ablation.median_ms}
    assert set(rows) == {"capt", "capt_without_dv", "pct_regression"} and len(ablation.results) == 12
    before = [r for r in ev.results if r.method == "capt"]
    assert [r.joints for r in rows["capt"]] == [r.joints for r in before]  # the double-voted row as before
    assert [r.pa for r in rows["capt_without_dv"]] == [r.pa for r in rows["capt"]]  # same segmentation
    assert [r.joints for r in rows["capt_without_dv"]] != [r.joints for r in rows["capt"]]
    assert "| box_revolute | capt_without_dv |" in ablation.table
    with pytest.raises(ValueError, match="needs a capt checkpoint"):
        evaluate([plain.best_path], data_dir, "test", progress=False, without_double_voting=True)

    # two checkpoints of one variant (e.g. before and after fine-tuning) keep a row each
    two = evaluate([resumed.best_path, straight.last_path], data_dir, "test", timing_clouds=3,
                   progress=False)
    names = [f"capt ({resumed.best_path})", f"capt ({straight.last_path})"]
    assert set(two.median_ms) == set(names) and len(two.results) == 8
    assert all(f"| box_revolute | {n} |" in two.table for n in names)
    with pytest.raises(ValueError, match="given twice"):
        evaluate([plain.best_path, plain.best_path], data_dir, "test", progress=False)

    # the same clouds in new poses: other inputs, so other errors; the segmentation counts stay paired
    posed = evaluate([resumed.best_path], data_dir, "test", timing_clouds=3, progress=False, test_pose="so3")
    assert len(posed.results) == 4
    assert [r.instance_id for r in posed.results] == [r.instance_id for r in before]
    assert [r.joints for r in posed.results] != [r.joints for r in before]
    with pytest.raises(ValueError, match="test_pose must be one of"):
        evaluate([resumed.best_path], data_dir, "test", progress=False, test_pose="tilted")

    # sensor corruption: other inputs, the same clouds and ground truth; stray points are not scored
    noisy = evaluate([resumed.best_path], data_dir, "test", timing_clouds=3, progress=False,
                     corruption=Corruption(jitter_m=0.01, outlier_fraction=0.2))
    assert [r.instance_id for r in noisy.results] == [r.instance_id for r in before]
    assert all(r.pa is not None and 0 <= r.pa <= 1 for r in noisy.results)
    assert [r.joints for r in noisy.results] != [r.joints for r in before]
    clean = evaluate([resumed.best_path], data_dir, "test", timing_clouds=3, progress=False,
                     corruption=Corruption())
    assert [(r.pa, r.joints) for r in clean.results] == [(r.pa, r.joints) for r in before]
    filtered = evaluate([resumed.best_path], data_dir, "test", timing_clouds=3, progress=False,
                        corruption=Corruption(outlier_fraction=0.2), outlier_filter=OutlierFilter())
    assert len(filtered.results) == 4 and all(r.pa is not None for r in filtered.results)


def test_resuming_with_more_epochs_replans_the_cosine_schedule(tmp_path, data_dir):
    import math

    out = tmp_path / "run"
    train(_cfg("capt", 2), data_dir, out)  # a finished 2-epoch plan ends at learning rate 0
    longer = train(_cfg("capt", 4), data_dir, out)
    rows = list(csv.DictReader(open(longer.log_path)))
    assert [r["epoch"] for r in rows] == ["0", "1", "2", "3"]
    base = _cfg("capt", 4).lr
    # epochs 2 and 3 of the extended plan run at the 4-epoch cosine's values, not at 0
    for epoch in (2, 3):
        expected = base * (1 + math.cos(math.pi * epoch / 4)) / 2
        assert float(rows[epoch]["lr"]) == pytest.approx(expected, rel=1e-5)  # the CSV keeps 6 digits


def test_init_from_starts_a_new_run_from_a_checkpoints_weights(tmp_path, data_dir):
    from perception.checkpoint import CheckpointError

    start = train(_cfg("capt", 2), data_dir, tmp_path / "start")
    weights = load_checkpoint(start.best_path).state_dict
    # no epoch run: best.pt is the starting checkpoint, scored on the validation split
    held = train(_cfg("capt", 3), data_dir, tmp_path / "held", stop_after=0, init_from=start.best_path)
    assert held.epochs_run == 0 and 0.0 < held.best_val_loss < float("inf")
    best = load_checkpoint(held.best_path)
    assert all(bool((best.state_dict[k] == weights[k]).all()) for k in weights)
    assert best.training["init_from"] == str(start.best_path)
    # training on from it: the best validation loss never exceeds the start's
    tuned = train(_cfg("capt", 3), data_dir, tmp_path / "tuned", init_from=start.best_path)
    assert tuned.epochs_run == 3 and tuned.best_val_loss <= held.best_val_loss
    assert load_checkpoint(tuned.last_path).training["init_from"] == str(start.best_path)
    # a checkpoint of another model configuration is refused, naming what differs
    with pytest.raises(CheckpointError):
        train(_cfg("pct_regression", 1), data_dir, tmp_path / "other", init_from=start.best_path)
