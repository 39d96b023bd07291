"""Dataset generation: deterministic shards, atomic resume, labels consistent with the ground truth."""

from __future__ import annotations

import json
from pathlib import Path

import numpy as np
import pytest

from capt_common.typed_yaml import ConfigError, from_dict
from capt_env.dataset.config import MAX_JOINTS, GenerateConfig
from capt_env.dataset.generator import generate, plan_shards, shard_path
from capt_env.tasks.config import CameraConfig

SMALL = GenerateConfig(
    category="drawer_cabinet",
    seed=3,
    counts={"train": 4, "val": 2, "test": 2},
    samples_per_shard=2,
    views_per_instance=2,
    num_points=256,
    min_object_points=100,
    camera=CameraConfig(width=96, height=96, random_view=True),
)


@pytest.fixture(scope="module")
def dataset(tmp_path_factory: pytest.TempPathFactory) -> Path:
    out = tmp_path_factory.mktemp("ds")
    generate(SMALL, out, workers=1, progress=False)
    return out


def test_layout_and_manifest(dataset: Path) -> None:
    manifest = json.loads((dataset / "manifest.json").read_text())
    assert manifest["complete"] and manifest["counts"] == {"train": 4, "val": 2, "test": 2}
    assert manifest["config"]["seed"] == 3 and manifest["versions"]["mani_skill"] == "3.0.1"
    shard = np.load(dataset / "train" / "shard_00000.npz")
    assert shard["points"].shape == (2, 256, 3) and shard["points"].dtype == np.float32
    assert shard["part_labels"].shape == (2, 256) and shard["part_labels"].min() >= 0
    assert shard["joint_dirs"].shape == (2, MAX_JOINTS, 3)
    assert shard["joint_mask"][:, 0].all()


def test_splits_use_their_own_instances(dataset: Path) -> None:
    from capt_env.objects.splits import split_of

    for split in ("train", "val", "test"):
        for path in (dataset / split).glob("shard_*.npz"):
            for iid in np.load(path)["instance_id"]:
                assert split_of("drawer_cabinet", int(iid)) == split


def test_labels_and_joints_are_consistent(dataset: Path) -> None:
    """Unit directions, states within limits, point labels only base or a joint's child part."""
    shard = np.load(dataset / "train" / "shard_00000.npz")
    for i in range(len(shard["points"])):
        mask = shard["joint_mask"][i]
        np.testing.assert_allclose(np.linalg.norm(shard["joint_dirs"][i][mask], axis=-1), 1.0, atol=1e-5)
        lo, hi = shard["joint_limits"][i][mask].T
        states = shard["joint_states"][i][mask]
        assert np.all(states >= lo - 1e-4) and np.all(states <= hi + 1e-4)
        child = shard["joint_child_part"][i][mask]
        labels = shard["part_labels"][i]
        assert set(np.unique(labels)) <= {0, *child.tolist()}


def test_deterministic_and_resumes_without_duplicates(dataset: Path, tmp_path: Path) -> None:
    job = plan_shards(SMALL)[1]
    again = tmp_path / "again"
    generate(SMALL, again, workers=1, progress=False)
    a, b = np.load(shard_path(dataset, job)), np.load(shard_path(again, job))
    np.testing.assert_array_equal(a["points"], b["points"])
    shard_path(again, job).unlink()  # as if interrupted before this shard
    result = generate(SMALL, again, workers=1, progress=False)
    assert result["rendered_now"] == job.num_samples
    assert result["skipped_shards"] == len(plan_shards(SMALL)) - 1
    np.testing.assert_array_equal(np.load(shard_path(again, job))["points"], a["points"])


def test_refuses_to_mix_configs(dataset: Path) -> None:
    import dataclasses

    with pytest.raises(ValueError, match="another config"):
        generate(dataclasses.replace(SMALL, seed=4), dataset, workers=1, progress=False)


def test_bad_config_values() -> None:
    with pytest.raises(ConfigError, match="unknown category"):
        from_dict(GenerateConfig, {"category": "toaster"})
    with pytest.raises(ConfigError, match="counts keys"):
        from_dict(GenerateConfig, {"counts": {"training": 5}})
    with pytest.raises(ConfigError, match="random_view"):
        from_dict(GenerateConfig, {"camera": {"random_view": False}})
