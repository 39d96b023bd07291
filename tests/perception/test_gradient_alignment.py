"""Gradient alignment of loss terms (perception/gradient_alignment.py): the per-term gradients are
the autograd gradients of each weighted term, and the summaries match hand-computed values."""

from __future__ import annotations

import math

import pytest
import torch

from perception.config import CaptConfig
from perception.gradient_alignment import (
    PARAMETER_GROUPS,
    alignments,
    cosine,
    group_parameters,
    term_gradients,
)
from perception.losses import motion_loss
from perception.model import CaptModel

from .helpers import collate, make_samples, tiny_model_config


def _model_and_batch(variant: str = "capt") -> tuple[CaptModel, dict[str, torch.Tensor], CaptConfig]:
    torch.manual_seed(0)
    cfg = CaptConfig(model=tiny_model_config(variant))
    return CaptModel(cfg.model), collate(make_samples(3), 128), cfg


def test_cosine_of_constructed_vectors():
    a = torch.tensor([1.0, 2.0, 0.0])
    assert cosine(a, 3 * a) == pytest.approx(1.0)
    assert cosine(a, -a) == pytest.approx(-1.0)
    assert cosine(a, torch.tensor([-2.0, 1.0, 5.0])) == pytest.approx(0.0, abs=1e-7)
    assert cosine(torch.tensor([1.0, 0.0]), torch.tensor([1.0, 1.0])) == pytest.approx(1 / math.sqrt(2))
    assert math.isnan(cosine(a, torch.zeros(3)))


def test_motion_gradient_is_the_weighted_motion_loss_gradient():
    model, batch, cfg = _model_and_batch()
    grads = term_gradients(model, batch, cfg, ("motion", "state", "seg"), motion_weight=0.1)
    model.eval()
    out = model(batch["points"])
    loss = 0.1 * motion_loss(batch["points"], out, batch, cfg.loss.motion_angle, cfg.loss.motion_distance)
    params = group_parameters(model, "shared")
    expected = torch.cat([g.reshape(-1) for g in torch.autograd.grad(loss, params)])
    assert torch.allclose(grads["motion"]["shared"], expected, atol=1e-7)
    assert float(grads["motion"]["shared"].norm()) > 0
    # the segmentation branch's loss never reaches the articulation branch's hidden layers
    assert float(grads["seg"]["articulation_shared"].abs().max()) == 0.0
    assert float(grads["seg"]["encoder"].norm()) > 0
    # "shared" is the encoder's vector followed by the articulation branch's
    cat = torch.cat([grads["state"]["encoder"], grads["state"]["articulation_shared"]])
    assert torch.equal(grads["state"]["shared"], cat)


def test_motion_weight_scales_the_gradient_also_for_capt_plain():
    model, batch, cfg = _model_and_batch("capt_plain")
    g1 = term_gradients(model, batch, cfg, ("motion",), motion_weight=0.1)["motion"]["shared"]
    g2 = term_gradients(model, batch, cfg, ("motion",), motion_weight=0.2)["motion"]["shared"]
    assert float(g1.norm()) > 0
    assert torch.allclose(g2, 2 * g1, rtol=1e-5, atol=1e-9)


def test_alignments_summarise_batches():
    ref = {"g": torch.tensor([1.0, 0.0])}
    batches = [{"state": ref, "motion": {"g": torch.tensor([2.0, 0.0])}},
               {"state": ref, "motion": {"g": torch.tensor([-1.0, 0.0])}},
               {"state": ref, "motion": {"g": torch.tensor([0.0, 3.0])}}]
    (row,) = alignments(batches, "state", ["motion"], ["g"])
    assert row.mean_cosine == pytest.approx(0.0)  # (1 - 1 + 0) / 3
    assert row.negative_share == pytest.approx(1 / 3)
    assert row.norm_ratio == pytest.approx(2.0)  # (2 + 1 + 3) / 3
    # summed: state (3, 0), motion (1, 3) -> cos = 3 / (3 * sqrt(10))
    assert row.summed_cosine == pytest.approx(1 / math.sqrt(10))
    assert row.batches == 3
    with pytest.raises(ValueError, match="no batches"):
        alignments([], "state", ["motion"])


def test_bad_requests_are_named():
    model, batch, cfg = _model_and_batch()
    with pytest.raises(ValueError, match="unknown parameter group 'head'"):
        group_parameters(model, "head")
    with pytest.raises(ValueError, match="unknown loss terms"):
        term_gradients(model, batch, cfg, ("state", "pivot"), 0.1)
    reg = CaptModel(tiny_model_config("pct_regression"))
    with pytest.raises(ValueError, match="per-point variant"):
        group_parameters(reg, PARAMETER_GROUPS[0])
