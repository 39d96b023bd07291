"""The cross-category model: joint slots of type ``any`` whose type (revolute, prismatic, absent) the
network predicts, datasets of several categories trained together, absent slots left out of the
estimate."""

from __future__ import annotations

from dataclasses import replace

import numpy as np
import torch

from perception.config import CaptConfig, TrainConfig
from perception.data import CaptShardDataset, Sample, fit_joint_slots, write_dataset
from perception.evaluation import evaluate
from perception.inference import ArticulationEstimator
from perception.losses import capt_losses, slot_type_targets
from perception.model import CaptModel
from perception.training import train

from .helpers import collate, make_samples, tiny_model_config


def cross_config(**kw) -> CaptConfig:
    model = tiny_model_config(max_parts=3, max_joints=2, joint_types=("any", "any"), joint_child_parts=(1, 2),
                              **kw)
    return CaptConfig(model=model)


def padded(sample: Sample, slots: int) -> Sample:
    """``sample`` with its joint arrays padded to ``slots`` (the extra slots absent)."""
    arrays = fit_joint_slots({k: np.asarray(v)[None] for k, v in sample.arrays().items()}, slots)
    return Sample.from_arrays({k: v[0] for k, v in arrays.items()})


def mixed_samples(n: int, seed: int) -> list[Sample]:
    """Alternating revolute (lid) and prismatic (drawer) box objects, two slots each."""
    rev, pri = make_samples(n, seed, "revolute"), make_samples(n, seed + 100, "prismatic")
    return [padded(rev[i] if i % 2 == 0 else pri[i], 2) for i in range(n)]


def test_slot_type_targets_mark_absent_slots():
    types = torch.tensor([[0, 1, -1], [1, -1, -1], [0, 0, 1]])
    mask = torch.tensor([[True, True, False], [True, False, False], [True, False, True]])
    expected = torch.tensor([[0, 1, 2], [1, 2, 2], [0, 2, 1]])
    assert torch.equal(slot_type_targets(types, mask), expected)


def test_only_any_slots_get_a_type_head():
    assert CaptModel(cross_config().model).slot_type_head is not None
    assert CaptModel(tiny_model_config()).slot_type_head is None
    out = CaptModel(cross_config().model).eval()(torch.rand(2, 128, 3))
    assert out.slot_type_logits.shape == (2, 2, 3)


def test_tiny_cross_category_model_overfits_eight_mixed_samples():
    torch.manual_seed(0)
    cfg = cross_config()
    samples = mixed_samples(8, seed=0)
    batch = collate(samples, 128)
    model = CaptModel(cfg.model)
    opt = torch.optim.Adam(model.parameters(), lr=2e-3)
    first = last = None
    for _ in range(200):
        parts = capt_losses(model(batch["points"]), batch, cfg)
        opt.zero_grad()
        parts["total"].backward()
        opt.step()
        first = float(parts["total"].detach()) if first is None else first
        last = float(parts["total"].detach())
    assert last < first / 10, (first, last)
    assert float(parts["slot_type"].detach()) < 0.05
    est = ArticulationEstimator(model, cfg, num_threads=1)
    for s in samples:
        joints = est.predict(np.asarray(s.points, np.float64)).joints
        assert [j.joint_index for j in joints] == [0]  # slot 1 is absent in every sample
        assert joints[0].type == ("revolute" if s.joint_types[0] == 0 else "prismatic")


def test_fixed_slots_keep_their_types_and_report_every_slot():
    cfg = CaptConfig(model=tiny_model_config())
    est = ArticulationEstimator(CaptModel(cfg.model), cfg, num_threads=1)
    joints = est.predict(np.asarray(make_samples(1)[0].points, np.float64)).joints
    assert [(j.joint_index, j.type) for j in joints] == [(0, "revolute")]


def test_training_on_two_category_datasets(tmp_path):
    dirs = []
    for jt, seed in (("revolute", 1), ("prismatic", 2)):
        splits = {"train": [padded(s, 2) for s in make_samples(8, seed, jt)],
                  "val": [padded(s, 2) for s in make_samples(4, seed + 10, jt)],
                  "test": [padded(s, 2) for s in make_samples(4, seed + 20, jt)]}
        dirs.append(write_dataset(tmp_path / jt, splits, samples_per_shard=8))
    cfg = cross_config()
    ds = CaptShardDataset(dirs, "train", cfg.model)
    assert len(ds) == 16 and set(ds.arrays["category"]) == {"box_revolute", "box_prismatic"}
    run = train(TrainConfig(model=cfg, epochs=1, batch_size=8, progress=False, device="cpu"), dirs,
                tmp_path / "run")
    scored = evaluate([run.best_path], dirs[1], progress=False, timing_clouds=1)
    assert {r.category for r in scored.results} == {"box_prismatic"}
    assert all(r.true_joints == 1 and 0 <= r.missed_joints <= 1 for r in scored.results)


def test_a_category_dataset_with_other_types_is_refused_by_a_fixed_model(tmp_path):
    d = write_dataset(tmp_path / "p", {"train": make_samples(2, 0, "prismatic")}, samples_per_shard=8)
    try:
        CaptShardDataset(d, "train", tiny_model_config())
    except ValueError as err:
        assert "joint types" in str(err)
    else:
        raise AssertionError("a revolute model accepted prismatic data")
    CaptShardDataset(d, "train", replace(tiny_model_config(), joint_types=("any",)))


def test_an_object_seen_with_every_slot_absent_keeps_its_likeliest_joint():
    cfg = cross_config()
    model = CaptModel(cfg.model).eval()
    last = model.slot_type_head.mlp[-1]
    with torch.no_grad():  # every slot "absent", slot 1 the least so, and prismatic over revolute
        last.weight.zero_()
        last.bias.copy_(torch.tensor([0.0, 1.0, 9.0, 0.0, 2.0, 5.0]))
    joints = ArticulationEstimator(model, cfg, num_threads=1).predict(
        np.asarray(make_samples(1)[0].points, np.float64)).joints
    assert [(j.joint_index, j.type) for j in joints] == [(1, "prismatic")]
