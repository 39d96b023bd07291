"""Sensor-noise augmentation of training clouds (``TrainConfig.sensor_noise``)."""

from __future__ import annotations

import numpy as np
import pytest

from capt_common.typed_yaml import ConfigError, load_yaml
from perception.config import CaptConfig, TrainConfig
from perception.corruption import Corruption
from perception.data import CaptShardDataset, add_sensor_noise, write_dataset
from perception.training import train

from .helpers import make_samples, tiny_model_config


def test_strays_take_their_nearest_points_part_and_the_joints_stay() -> None:
    sample = make_samples(1, num_points=400)[0]
    labels = np.asarray(sample.part_labels)
    n_obj = int((labels >= 0).sum())
    noise = Corruption(jitter_m=0.001, outlier_fraction=0.25)
    noisy = add_sensor_noise(sample, np.random.default_rng(0), noise)
    assert len(noisy.points) == n_obj + round(0.25 * n_obj) and (noisy.part_labels >= 0).all()
    obj_pts = np.asarray(sample.points)[labels >= 0]
    for p, lab in zip(noisy.points[n_obj:], noisy.part_labels[n_obj:], strict=True):
        nearest = np.argmin(np.linalg.norm(obj_pts - p, axis=1))
        assert lab == labels[labels >= 0][nearest]
    np.testing.assert_array_equal(noisy.joint_dirs, sample.joint_dirs)
    np.testing.assert_array_equal(noisy.joint_pivots, sample.joint_pivots)
    assert add_sensor_noise(sample, np.random.default_rng(0), Corruption()) is sample


def test_only_augmented_clouds_get_noise_and_a_new_draw_each_epoch(tmp_path) -> None:
    data = write_dataset(tmp_path / "d", {"train": make_samples(2, seed=1)}, samples_per_shard=8)
    cfg = tiny_model_config()
    noise = Corruption(jitter_m=0.01, outlier_fraction=0.2)
    plain = CaptShardDataset(data, "train", cfg, augment=True, seed=0)
    noisy = CaptShardDataset(data, "train", cfg, augment=True, seed=0, sensor_noise=noise)
    assert not np.allclose(plain[0]["points"].numpy(), noisy[0]["points"].numpy())
    first = noisy[0]["points"].numpy()
    noisy.set_epoch(1)
    assert not np.allclose(first, noisy[0]["points"].numpy())
    unaugmented = CaptShardDataset(data, "train", cfg, augment=False, sensor_noise=noise)
    clean = CaptShardDataset(data, "train", cfg, augment=False)
    np.testing.assert_array_equal(unaugmented[0]["points"].numpy(), clean[0]["points"].numpy())


def test_sensor_noise_is_read_from_yaml_and_checked(tmp_path) -> None:
    good = tmp_path / "good.yaml"
    good.write_text("sensor_noise: {jitter_m: 0.002, outlier_fraction: 0.1}\n")
    assert load_yaml(TrainConfig, good).sensor_noise == Corruption(0.002, 0.1)
    assert TrainConfig().sensor_noise.is_clean
    for text, message in (("sensor_noise: {jitter_m: -0.002}\n", "sensor_noise: jitter_m must be"),
                          ("sensor_noise: {outliers: 0.1}\n", r"unknown key\(s\) \['outliers'\]")):
        bad = tmp_path / "bad.yaml"
        bad.write_text(text)
        with pytest.raises(ConfigError, match=message):
            load_yaml(TrainConfig, bad)


def test_a_run_with_sensor_noise_trains_and_records_it(tmp_path) -> None:
    data = write_dataset(tmp_path / "d", {"train": make_samples(8, seed=1), "val": make_samples(2, seed=2)},
                         samples_per_shard=8)
    cfg = TrainConfig(model=CaptConfig(model=tiny_model_config()), epochs=1, batch_size=4, progress=False,
                      device="cpu", sensor_noise=Corruption(jitter_m=0.003, outlier_fraction=0.1))
    run = train(cfg, data, tmp_path / "run")
    from perception.checkpoint import load_checkpoint

    noise = load_checkpoint(run.last_path).training["train_config"]["sensor_noise"]
    assert noise == {"jitter_m": 0.003, "outlier_fraction": 0.1}
