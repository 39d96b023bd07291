"""Checkpoints (safe load, version/config checks) and the public inference API."""

from __future__ import annotations

from dataclasses import replace
from pathlib import Path
from unittest import mock

import numpy as np
import pytest
import torch

from perception.checkpoint import FORMAT_VERSION, CheckpointError, load_checkpoint, save_checkpoint
from perception.config import CaptConfig
from perception.inference import ArticulationEstimator
from perception.model import CaptModel

from .helpers import make_samples, tiny_model_config


def _save(tmp_path: Path, variant: str = "capt", **kw) -> tuple[Path, CaptModel, CaptConfig]:
    torch.manual_seed(0)
    cfg = CaptConfig(model=tiny_model_config(variant, **kw))
    model = CaptModel(cfg.model).eval()
    path = save_checkpoint(tmp_path / f"{variant}.pt", cfg, model.state_dict(), (0.4, 1.8), "box_revolute",
                           {"epochs": 1})
    return path, model, cfg


def test_round_trip_identical_outputs_and_metadata(tmp_path):
    path, model, cfg = _save(tmp_path)
    ckpt = load_checkpoint(path, expected_model=cfg.model)
    assert ckpt.config == cfg and ckpt.voting_window == (0.4, 1.8) and ckpt.category == "box_revolute"
    again = CaptModel(ckpt.config.model).eval()
    again.load_state_dict(ckpt.state_dict)
    x = torch.randn(2, 128, 3)
    with torch.no_grad():
        a, b = model(x), again(x)
    for name in ("seg_logits", "dir", "dist", "pdir", "state"):
        assert torch.equal(getattr(a, name), getattr(b, name))


def test_load_uses_weights_only(tmp_path):
    path, _, _ = _save(tmp_path)
    real = torch.load
    with mock.patch("torch.load", side_effect=real) as spy:
        load_checkpoint(path)
    assert spy.call_args.kwargs.get("weights_only") is True


def test_wrong_version_and_config_mismatch_raise(tmp_path):
    path, _, cfg = _save(tmp_path)
    payload = torch.load(path, weights_only=True)
    payload["format_version"] = FORMAT_VERSION + 1
    torch.save(payload, tmp_path / "v2.pt")
    with pytest.raises(CheckpointError, match="format_version"):
        load_checkpoint(tmp_path / "v2.pt")
    with pytest.raises(CheckpointError, match="embed_dim"):
        load_checkpoint(path, expected_model=tiny_model_config(embed_dim=64))
    payload["format_version"] = FORMAT_VERSION
    payload["metadata"] = payload["metadata"].replace('"knn_k"', '"knn_kk"')
    torch.save(payload, tmp_path / "badcfg.pt")
    with pytest.raises(CheckpointError, match="config"):
        load_checkpoint(tmp_path / "badcfg.pt")
    with pytest.raises(CheckpointError, match="not found"):
        load_checkpoint(tmp_path / "missing.pt")


def test_predict_outputs_in_caller_frame(tmp_path):
    path, _, _ = _save(tmp_path)
    est = ArticulationEstimator.from_checkpoint(path)
    assert est.voting_window == (0.4, 1.8)
    sample = make_samples(1, num_points=300)[0]
    pts = sample.points.astype(np.float64) + np.array([2.0, -1.0, 0.5])
    r1, r2 = est.predict(pts), est.predict(pts)
    assert r1.part_labels.shape == (300,) and r1.part_labels.dtype == np.int64
    assert set(np.unique(r1.part_labels)) <= {0, 1}
    (j,) = r1.joints
    assert j.type == "revolute" and abs(np.linalg.norm(j.direction) - 1) < 1e-9 and 0 <= j.confidence <= 1
    assert np.array_equal(r1.part_labels, r2.part_labels) and np.allclose(j.pivot, r2.joints[0].pivot)
    # Equivariance of the frame handling: shifting the input shifts the pivot line, direction unchanged.
    r3 = est.predict(pts + np.array([0.0, 0.0, 3.0]))
    assert np.allclose(r3.joints[0].direction, j.direction, atol=1e-5)
    foot_shift = r3.joints[0].pivot - j.pivot - np.array([0.0, 0.0, 3.0])
    assert np.linalg.norm(np.cross(foot_shift, j.direction)) < 1e-4
    batch = est.predict_batch([pts, pts[:100]])
    assert len(batch) == 2 and batch[1].part_labels.shape == (100,) and batch[0].latency_ms > 0
    assert np.allclose(batch[0].joints[0].direction, j.direction, atol=1e-5)


def test_predict_regression_variant_and_prismatic_states(tmp_path):
    path, _, _ = _save(tmp_path, "pct_regression", joint_types=("prismatic",))
    est = ArticulationEstimator.from_checkpoint(path)
    pts = make_samples(1, joint_type="prismatic", num_points=200)[0].points.astype(np.float64)
    r = est.predict(pts)
    assert (r.part_labels == -1).all() and r.joints[0].type == "prismatic"
    r2 = est.predict(pts * 2.0)  # prismatic states are lengths: they scale with the cloud
    assert r2.joints[0].state == pytest.approx(2.0 * r.joints[0].state, rel=1e-4, abs=1e-6)


def test_double_voting_can_be_switched_off_for_capt_only(tmp_path):
    path, model, cfg = _save(tmp_path)
    pts = make_samples(1, num_points=300)[0].points.astype(np.float64)
    fine = ArticulationEstimator.from_checkpoint(path).predict(pts).joints[0]
    coarse_est = ArticulationEstimator.from_checkpoint(path, double_voting=False)
    coarse = coarse_est.predict(pts).joints[0]
    # The same weights read as CAPT-plain vote once, over all points: exactly "CAPT w/o DV".
    plain_cfg = CaptConfig(model=replace(cfg.model, variant="capt_plain"))
    plain = ArticulationEstimator(model, plain_cfg, (0.4, 1.8)).predict(pts).joints[0]
    assert np.allclose(coarse.direction, plain.direction) and np.allclose(coarse.pivot, plain.pivot)
    assert coarse.state == pytest.approx(plain.state) and coarse.confidence == pytest.approx(plain.confidence)
    assert not np.allclose(fine.pivot, coarse.pivot)  # the fine vote keeps a subset of the points
    assert coarse_est.double_voting is False and ArticulationEstimator.from_checkpoint(path).double_voting
    with pytest.raises(ValueError, match="needs a capt checkpoint"):
        ArticulationEstimator(model, plain_cfg, double_voting=True)
    pct_path, _, _ = _save(tmp_path, "pct_regression")
    with pytest.raises(ValueError, match="does not vote"):
        ArticulationEstimator.from_checkpoint(pct_path, double_voting=False)


@pytest.mark.parametrize(
    ("points", "message"),
    [
        (np.full((100, 3), np.nan), "NaN or inf"),
        (np.concatenate([np.zeros((99, 3)), [[np.inf, 0, 0]]]), "NaN or inf"),
        (np.zeros((10, 3)), "too few points"),
        (np.zeros((100, 2)), r"shape \(N, 3\)"),
        (np.zeros((2, 100, 3)), r"shape \(N, 3\)"),
        (np.zeros((100, 3), dtype=np.int64), "float"),
        (np.zeros((0, 3)), "empty"),
        ([[0.0, 0.0, 0.0]] * 100, "numpy array"),
    ],
)
def test_predict_rejects_bad_input(tmp_path, points, message):
    path, _, _ = _save(tmp_path)
    est = ArticulationEstimator.from_checkpoint(path)
    with pytest.raises(ValueError, match=message):
        est.predict(points)


def test_the_outlier_filter_feeds_only_the_inliers(tmp_path):
    from perception.outlier_filter import OutlierFilter, inlier_mask

    path, _, _ = _save(tmp_path)
    pts = make_samples(1, num_points=300)[0].points.astype(np.float64)
    far = pts.mean(axis=0) + np.random.default_rng(1).normal(0, 1.0, (15, 3))  # strays around the object
    noisy = np.concatenate([pts, far])
    filt = OutlierFilter()
    keep = inlier_mask(noisy, filt)
    assert not keep[300:].any()
    plain = ArticulationEstimator.from_checkpoint(path)
    filtered = ArticulationEstimator.from_checkpoint(path, outlier_filter=filt).predict(noisy)
    # the filter's answer is the unfiltered estimator's on the kept points; every input point is labelled
    same = plain.predict(noisy[keep]).joints[0]
    assert filtered.part_labels.shape == (315,)
    assert np.allclose(filtered.joints[0].direction, same.direction, atol=1e-6)
    assert np.allclose(filtered.joints[0].pivot, same.pivot, atol=1e-6)
    # and the strays change the unfiltered answer (they move the bounding box the cloud is normalised by)
    assert not np.allclose(plain.predict(noisy).joints[0].pivot, same.pivot, atol=1e-3)
