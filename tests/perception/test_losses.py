"""Losses (paper Sec. III-B/C): motion loss behaviour, masking, and a tiny model that overfits."""

from __future__ import annotations

import math

import numpy as np
import torch

from perception.config import CaptConfig, LossConfig, LossWeights
from perception.geometry import rotate_about_axis
from perception.losses import capt_losses, motion_loss
from perception.model import CaptModel, CaptOutput

from .helpers import collate, make_samples, tiny_model_config


def _perfect_output(batch: dict[str, torch.Tensor]) -> CaptOutput:
    n = batch["points"].shape[1]
    return CaptOutput(dir=batch["joint_dirs"].unsqueeze(1).expand(-1, n, -1, -1).clone(),
                      dist=batch["dist"].clone(), pdir=batch["pdir"].clone(),
                      state=batch["joint_states"].unsqueeze(1).expand(-1, n, -1).clone())


def _tilted(out: CaptOutput, batch, angle: float, offset: float) -> CaptOutput:
    """Predicted axis = true axis tilted by ``angle`` about a perpendicular through the true pivot, then
    shifted by ``offset`` perpendicular to it; per-point dist/pdir re-derived for that axis."""
    from perception.geometry import axis_targets

    u, q = batch["joint_dirs"][:, 0].double(), batch["joint_pivots"][:, 0].double()
    perp = torch.linalg.cross(u, torch.tensor([[0.3, 0.5, 0.8]], dtype=torch.float64).expand_as(u), dim=-1)
    perp = perp / perp.norm(dim=-1, keepdim=True)
    u2 = rotate_about_axis(u, perp, torch.zeros_like(u), angle)
    q2 = q + offset * perp
    dist, pdir = axis_targets(batch["points"].double(), u2, q2)
    n = batch["points"].shape[1]
    return CaptOutput(dir=u2[:, None, None].expand(-1, n, 1, -1).float(), dist=dist[..., None].float(),
                      pdir=pdir[:, :, None].float(), state=out.state)


def test_motion_loss_zero_at_truth_and_monotone():
    batch = collate(make_samples(4), 128)
    perfect = _perfect_output(batch)
    assert float(motion_loss(batch["points"], perfect, batch, math.pi / 2, 0.5)) < 1e-5
    by_angle = [float(motion_loss(batch["points"], _tilted(perfect, batch, a, 0.0), batch, math.pi / 2, 0.5))
                for a in np.radians([0, 2, 5, 10, 20, 40])]
    by_offset = [float(motion_loss(batch["points"], _tilted(perfect, batch, 0.0, d), batch, math.pi / 2, 0.5))
                 for d in [0.0, 0.01, 0.03, 0.1, 0.3]]
    assert by_angle[0] < 1e-5 and by_offset[0] < 1e-5
    assert all(b > a for a, b in zip(by_angle, by_angle[1:], strict=False))
    assert all(b > a for a, b in zip(by_offset, by_offset[1:], strict=False))
    # A pure offset d of a quarter-turn axis moves every point by |R d - d| = sqrt(2) d.
    assert abs(by_offset[3] - math.sqrt(2) * 0.1) < 1e-4


def test_all_losses_vanish_at_truth_and_flipped_direction_costs():
    batch = collate(make_samples(3), 128)
    cfg = CaptConfig(model=tiny_model_config())
    out = _perfect_output(batch)
    logits = torch.nn.functional.one_hot(batch["part_labels"], 2).float() * 50.0
    out.seg_logits = logits
    parts = capt_losses(out, batch, cfg)
    assert float(parts["total"]) < 1e-4
    out.dir = -out.dir
    parts = capt_losses(out, batch, cfg)
    assert abs(float(parts["dir"]) - 2.0) < 1e-5 and float(parts["motion"]) > 0.01


def test_prismatic_masks_position_terms_and_absent_joints_count_zero():
    batch = collate(make_samples(2, joint_type="prismatic"), 128)
    cfg = CaptConfig(model=tiny_model_config(joint_types=("prismatic",)))
    out = _perfect_output(batch)
    out.dist = out.dist + 5.0  # meaningless for prismatic joints: must not be penalised
    out.pdir = -out.pdir
    parts = capt_losses(out, batch, cfg)
    assert float(parts["dist"]) == 0.0 and float(parts["pdir"]) == 0.0
    assert float(parts["motion"]) < 1e-6
    batch["joint_mask"][:] = False
    out.dir = -out.dir
    parts = capt_losses(out, batch, cfg)
    assert float(parts["dir"]) == 0.0 and float(parts["motion"]) == 0.0


def test_capt_plain_has_no_motion_term():
    cfg = CaptConfig(model=tiny_model_config("capt_plain"), loss=LossConfig(weights=LossWeights(motion=5.0)))
    assert cfg.effective_loss_weights().motion == 0.0
    assert not cfg.double_voting


def test_tiny_model_overfits_eight_samples():
    torch.manual_seed(0)
    cfg = CaptConfig(model=tiny_model_config())
    batch = collate(make_samples(8), 128)
    model = CaptModel(cfg.model)
    opt = torch.optim.Adam(model.parameters(), lr=2e-3)
    first = None
    for step in range(120):
        parts = capt_losses(model(batch["points"]), batch, cfg)
        opt.zero_grad()
        parts["total"].backward()
        opt.step()
        if first is None:
            first = float(parts["total"].detach())
        last = float(parts["total"].detach())
        if last < first / 10 and step > 20:
            break
    assert last < first / 10, (first, last, step)


def test_regression_variant_losses():
    torch.manual_seed(0)
    cfg = CaptConfig(model=tiny_model_config("pct_regression"))
    batch = collate(make_samples(4), 128)
    model = CaptModel(cfg.model)
    out = model(batch["points"])
    assert out.seg_logits is None and out.dir is None and out.reg_dir.shape == (4, 1, 3)
    parts = capt_losses(out, batch, cfg)
    assert set(parts) >= {"dir", "pivot", "state", "total"} and torch.isfinite(parts["total"])
    parts["total"].backward()
