"""Fixed seeded poses of validation and test clouds (``capt evaluate --test-pose``, ``val_pose``)."""

from __future__ import annotations

import numpy as np
import pytest

from capt_common.typed_yaml import ConfigError, load_yaml
from perception.config import TrainConfig
from perception.data import CaptShardDataset, posed_sample, write_dataset
from perception.voting import point_axis_distance

from .helpers import make_samples, tiny_model_config


def _pairwise(points: np.ndarray) -> np.ndarray:
    return np.linalg.norm(points[:, None] - points[None], axis=-1)


@pytest.mark.parametrize("pose", ["yaw", "so3"])
def test_a_pose_is_rigid_and_moves_the_labels_with_the_cloud(pose: str) -> None:
    sample = make_samples(1, seed=4)[0]
    posed = posed_sample(sample, 7, pose)
    pts, new = np.asarray(sample.points, np.float64), np.asarray(posed.points, np.float64)
    assert np.abs(new - pts).max() > 0.05  # it moved
    np.testing.assert_allclose(_pairwise(new), _pairwise(pts), atol=1e-9)  # no scaling, no shear
    u, q = np.asarray(sample.joint_dirs[0], np.float64), np.asarray(sample.joint_pivots[0], np.float64)
    u2, q2 = np.asarray(posed.joint_dirs[0]), np.asarray(posed.joint_pivots[0])
    assert np.linalg.norm(u2) == pytest.approx(1.0)
    # every point keeps its distance to the joint axis, so the targets and metres are unchanged
    np.testing.assert_allclose(point_axis_distance(new, u2, q2), point_axis_distance(pts, u, q), atol=1e-9)
    np.testing.assert_array_equal(posed.part_labels, sample.part_labels)
    np.testing.assert_allclose(posed.joint_states, sample.joint_states)  # a rigid move keeps the state
    if pose == "yaw":
        assert u2[2] == pytest.approx(u[2])  # about +z: the axis keeps its height component


def test_poses_are_drawn_from_the_index_alone() -> None:
    sample = make_samples(1, seed=4)[0]
    a, b = posed_sample(sample, 3, "so3"), posed_sample(sample, 3, "so3")
    np.testing.assert_array_equal(a.points, b.points)
    c = posed_sample(sample, 4, "so3")
    assert np.abs(np.asarray(c.points) - np.asarray(a.points)).max() > 1e-3
    assert posed_sample(sample, 3, "world") is sample


def test_an_unknown_pose_is_named() -> None:
    with pytest.raises(ValueError, match="pose must be one of .*'tilted'"):
        posed_sample(make_samples(1)[0], 0, "tilted")


def test_a_posed_split_feeds_the_posed_clouds_to_the_model(tmp_path) -> None:
    data = write_dataset(tmp_path / "data", {"val": make_samples(3, seed=2)}, samples_per_shard=8)
    cfg = tiny_model_config()
    world = CaptShardDataset(data, "val", cfg)
    posed = CaptShardDataset(data, "val", cfg, pose="so3")
    for i in range(3):
        np.testing.assert_array_equal(posed.posed(i).points, posed_sample(world.sample(i), i, "so3").points)
    # the model's input is normalised, so compare the direction targets: the rotation shows there
    a, b = world[1], posed[1]
    assert float((a["joint_dirs"] - b["joint_dirs"]).abs().max()) > 0.05
    assert float((a["joint_dirs"] - posed[1]["joint_dirs"]).abs().max()) > 0.05  # same pose every call
    np.testing.assert_array_equal(b["joint_dirs"].numpy(), posed[1]["joint_dirs"].numpy())
    with pytest.raises(ValueError, match="pose must be one of .*'upside'"):
        CaptShardDataset(data, "val", cfg, pose="upside")


def test_val_pose_is_read_from_yaml_and_checked(tmp_path) -> None:
    good = tmp_path / "good.yaml"
    good.write_text("rotation_augmentation: so3\nval_pose: so3\n")
    assert load_yaml(TrainConfig, good).val_pose == "so3"
    assert TrainConfig().val_pose == "world"
    bad = tmp_path / "bad.yaml"
    bad.write_text("val_pose: tilted\n")
    with pytest.raises(ConfigError, match="val_pose"):
        load_yaml(TrainConfig, bad)
