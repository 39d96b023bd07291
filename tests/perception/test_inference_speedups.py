"""Exact rewrites on the inference path: batch norms folded into the layers before them, the attention's
column normalisation applied after its product, the k-d tree label lookup, and the thread setting."""

from __future__ import annotations

import numpy as np
import pytest
import torch

from perception.batchnorm_folding import fold_batchnorm
from perception.config import CaptConfig
from perception.encoder import OffsetAttention
from perception.inference import ArticulationEstimator, nearest_labels, torch_threads
from perception.model import CaptModel

from .helpers import tiny_model_config


def _randomised_batchnorms(model: torch.nn.Module, seed: int) -> None:
    gen = torch.Generator().manual_seed(seed)
    with torch.no_grad():
        for m in model.modules():
            if isinstance(m, torch.nn.modules.batchnorm._BatchNorm):
                m.running_mean.copy_(torch.rand(m.num_features, generator=gen) - 0.5)
                m.running_var.copy_(torch.rand(m.num_features, generator=gen) + 0.5)
                m.weight.copy_(torch.rand(m.num_features, generator=gen) * 2 - 1)  # some negative scales
                m.bias.copy_(torch.rand(m.num_features, generator=gen) - 0.5)


@pytest.mark.parametrize("variant", ["capt", "pct_regression"])
def test_folded_model_gives_the_same_outputs(variant):
    torch.manual_seed(0)
    model = CaptModel(tiny_model_config(variant)).eval()
    _randomised_batchnorms(model, 1)
    folded = fold_batchnorm(model)
    assert not any(isinstance(m, torch.nn.BatchNorm1d) for m in folded.modules())
    x = torch.rand(2, model.config.num_points, 3) - 0.5
    with torch.no_grad():
        ref, out = model(x), folded(x)
    for name in ("seg_logits", "dir", "dist", "pdir", "state", "reg_dir", "reg_pivot", "reg_state"):
        a, b = getattr(ref, name), getattr(out, name)
        assert (a is None) == (b is None), name
        if a is not None:
            torch.testing.assert_close(b, a, rtol=1e-4, atol=1e-5)


def test_folding_leaves_the_trained_model_alone():
    model = CaptModel(tiny_model_config()).train()
    before = {k: v.clone() for k, v in model.state_dict().items()}
    fold_batchnorm(model)
    assert model.training
    assert all(torch.equal(before[k], v) for k, v in model.state_dict().items())
    assert any(isinstance(m, torch.nn.BatchNorm1d) for m in model.modules())


def test_attention_normalises_columns_as_pct_does():
    torch.manual_seed(3)
    layer = OffsetAttention(16).eval()
    x = torch.randn(2, 16, 40)
    with torch.no_grad():
        q = layer.qk(x)
        attn = torch.softmax(torch.bmm(q.transpose(1, 2), q), dim=-1)
        attn = attn / (1e-9 + attn.sum(dim=1, keepdim=True))
        ref = x + layer.act(layer.norm(layer.trans(x - torch.bmm(layer.v(x), attn))))
        torch.testing.assert_close(layer(x), ref, rtol=1e-5, atol=1e-5)


def test_nearest_labels_matches_brute_force():
    rng = np.random.default_rng(0)
    ref, query = rng.normal(size=(200, 3)), rng.normal(size=(500, 3))
    labels = rng.integers(0, 4, size=200)
    brute = labels[np.argmin(((query[:, None] - ref[None]) ** 2).sum(-1), axis=1)]
    np.testing.assert_array_equal(nearest_labels(query, ref, labels), brute)


def test_predict_runs_with_its_thread_count_and_restores_the_callers():
    cfg = CaptConfig(model=tiny_model_config())
    est = ArticulationEstimator(CaptModel(cfg.model), cfg, num_threads=1)
    seen = []
    forward = est.model.forward
    est.model.forward = lambda x: (seen.append(torch.get_num_threads()), forward(x))[1]
    before = torch.get_num_threads()
    with torch_threads(2):
        est.predict(np.random.default_rng(0).uniform(-0.3, 0.3, size=(300, 3)))
        assert torch.get_num_threads() == 2
    assert seen == [1]
    assert torch.get_num_threads() == before
