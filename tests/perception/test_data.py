"""Data side: normalisation, augmentation label consistency, shard reader determinism, YAML configs."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest
import torch

from capt_common.typed_yaml import ConfigError, from_dict, load_yaml
from perception.config import CaptConfig, ModelConfig, TrainConfig
from perception.data import CaptShardDataset, Sample, augment, load_split, prepare_sample, write_dataset
from perception.geometry import axis_targets
from perception.normalisation import Normalisation

from .helpers import make_samples, tiny_model_config

CONFIGS = Path(__file__).resolve().parents[2] / "configs" / "perception"


def test_normalisation_inverse_is_exact_and_unit_diagonal():
    rng = np.random.default_rng(1)
    pts = rng.normal(size=(200, 3)) * [0.3, 0.1, 0.05] + [1.0, 2.0, -3.0]
    n = Normalisation.fit(pts)
    x = n.points(pts)
    assert np.linalg.norm(x.max(0) - x.min(0)) == pytest.approx(1.0)
    assert np.allclose((x.max(0) + x.min(0)) / 2, 0.0, atol=1e-12)
    assert np.allclose(n.points_inv(x), pts, atol=1e-12)
    s = np.array([0.7, 0.05])
    prism = np.array([False, True])
    assert np.allclose(n.states_inv(n.states(s, prism), prism), s)
    assert n.states(s, prism)[0] == 0.7 and n.states(s, prism)[1] == pytest.approx(0.05 / n.scale)


@pytest.mark.parametrize("joint_type", ["revolute", "prismatic"])
def test_augmentation_keeps_labels_consistent(joint_type):
    s = make_samples(1, joint_type=joint_type)[0]
    a = augment(s, np.random.default_rng(3))
    # Distances to the axis scale by s; rotation/translation preserve them.
    d0, _ = axis_targets(torch.as_tensor(s.points, dtype=torch.float64), torch.as_tensor(s.joint_dirs[0],
                         dtype=torch.float64), torch.as_tensor(s.joint_pivots[0], dtype=torch.float64))
    d1, p1 = axis_targets(torch.as_tensor(a.points), torch.as_tensor(a.joint_dirs[0]),
                          torch.as_tensor(a.joint_pivots[0]))
    ratio = (d1 / d0.clamp_min(1e-9))[d0 > 1e-3]
    assert torch.allclose(ratio, ratio.mean().expand_as(ratio), atol=1e-5)
    scale = float(ratio.mean())
    assert 0.8 <= scale <= 1.2
    expected_state = s.joint_states[0] * (scale if joint_type == "prismatic" else 1.0)
    assert a.joint_states[0] == pytest.approx(expected_state, rel=1e-5)
    assert np.linalg.norm(a.joint_dirs[0]) == pytest.approx(1.0)
    # Pairwise distances scale uniformly: the transform is rigid + uniform scale for labels and points.
    i, j = np.arange(0, 200, 7), np.arange(3, 203, 7)
    d_pts0 = np.linalg.norm(s.points[i] - s.points[j], axis=1)
    d_pts1 = np.linalg.norm(a.points[i] - a.points[j], axis=1)
    assert np.allclose(d_pts1, scale * d_pts0, rtol=1e-4, atol=1e-6)
    # Per-point targets recomputed in the normalised frame put every foot point on the augmented axis.
    item = prepare_sample(a, 128, np.random.default_rng(0))
    foot = item["points"] + item["dist"][:, 0, None] * item["pdir"][:, 0]
    d_check, _ = axis_targets(foot.double(), item["joint_dirs"][0].double(), item["joint_pivots"][0].double())
    if joint_type == "revolute":
        assert float(d_check.max()) < 1e-5


def test_prepare_sample_targets_match_points():
    s = make_samples(1)[0]
    item = prepare_sample(s, 64, np.random.default_rng(0))
    d, p = axis_targets(item["points"].double(), item["joint_dirs"][0].double(),
                        item["joint_pivots"][0].double())
    assert torch.allclose(item["dist"][:, 0].double(), d, atol=1e-5)
    assert torch.allclose(item["pdir"][:, 0].double(), p, atol=1e-5)
    extent = item["points"].max(0).values - item["points"].min(0).values
    assert float(extent.norm()) == pytest.approx(1.0, abs=1e-5)


def test_dataset_reader_deterministic_and_epoch_dependent(tmp_path):
    samples = make_samples(6)
    samples[0].part_labels[:5] = -1  # background points are dropped
    write_dataset(tmp_path, {"train": samples}, samples_per_shard=4)
    assert len(list((tmp_path / "train").glob("shard_*.npz"))) == 2
    assert load_split(tmp_path, "train")["points"].shape == (6, 256, 3)
    cfg = tiny_model_config()
    a = CaptShardDataset(tmp_path, "train", cfg, augment=True, seed=7)
    b = CaptShardDataset(tmp_path, "train", cfg, augment=True, seed=7)
    for i in range(len(a)):
        x, y = a[i], b[i]
        assert all(torch.equal(x[k], y[k]) for k in x)
    assert (a[0]["part_labels"] >= 0).all()
    a.set_epoch(1)
    assert not torch.equal(a[2]["joint_dirs"], b[2]["joint_dirs"])
    with pytest.raises(ValueError, match="joint types"):
        CaptShardDataset(tmp_path, "train", tiny_model_config(joint_types=("prismatic",)))
    one = tmp_path / "one.npz"
    samples[1].save(one)
    back = Sample.load(one)
    assert np.array_equal(back.points, samples[1].points) and back.category == samples[1].category


def test_yaml_configs_load_and_validate():
    for name in ("capt", "capt_plain", "pct_regression"):
        cfg = load_yaml(TrainConfig, CONFIGS / f"{name}.yaml")
        assert cfg.model.model.variant == name
    with pytest.raises(ConfigError, match="joint_types"):
        from_dict(ModelConfig, {"max_joints": 2})
    with pytest.raises(ConfigError, match="w0"):
        from_dict(CaptConfig, {"voting": {"w0": 2.0, "w1": 1.0}})
    with pytest.raises(ConfigError, match="unknown"):
        from_dict(TrainConfig, {"epochs": 2, "bogus": 1})


def test_yaw_rotation_keeps_up_direction() -> None:
    import numpy as np

    from perception.data import random_rotation

    rng = np.random.default_rng(0)
    for _ in range(5):
        rot = random_rotation(rng, "yaw")
        np.testing.assert_allclose(rot @ np.array([0.0, 0.0, 1.0]), [0.0, 0.0, 1.0], atol=1e-12)
        np.testing.assert_allclose(rot @ rot.T, np.eye(3), atol=1e-12)
    full = random_rotation(rng, "so3")
    assert abs((full @ np.array([0.0, 0.0, 1.0]))[2]) < 1.0


def _two_door_arrays() -> dict[str, np.ndarray]:
    """One stacked sample of a double door: base (0), left door (1, joint 0), right door (2, joint 1),
    the task's target the right door."""
    return {
        "part_labels": np.array([[0, 0, 1, 1, 2, 2, -1]]),
        "joint_types": np.array([[0, 0]]), "joint_dirs": np.array([[[0.0, 0, -1], [0, 0, 1]]]),
        "joint_pivots": np.array([[[0.0, -0.4, 0], [0, 0.4, 0]]]), "joint_states": np.array([[0.1, 0.3]]),
        "joint_limits": np.array([[[0.0, 1.5], [0, 1.5]]]), "joint_child_part": np.array([[1, 2]]),
        "joint_mask": np.array([[True, True]]), "target_joint": np.array([1]),
    }


def test_a_model_with_fewer_slots_is_scored_on_the_target_joint_only() -> None:
    from perception.data import TARGET_ONLY_KEY, fit_joint_slots, target_joint_only

    a = _two_door_arrays()
    with pytest.raises(ValueError, match="slots >= 1"):  # training never drops a joint
        fit_joint_slots(a, 1)
    out = fit_joint_slots(target_joint_only(a, 1), 1)
    # the right door in the one slot, its part that slot's part, the left door counted as fixed
    assert out["joint_mask"].tolist() == [[True]] and out["target_joint"].tolist() == [0]
    np.testing.assert_allclose(out["joint_dirs"][0, 0], [0, 0, 1])
    assert out["joint_states"][0, 0] == pytest.approx(0.3) and out["joint_child_part"].tolist() == [[1]]
    assert out["part_labels"].tolist() == [[0, 0, 0, 0, 1, 1, -1]]
    assert out[TARGET_ONLY_KEY].tolist() == [True]
    # a model with a slot for every joint scores the sample as it is
    kept = fit_joint_slots(target_joint_only(a, 2), 2)
    assert kept["part_labels"].tolist() == a["part_labels"].tolist() and not kept[TARGET_ONLY_KEY].any()
