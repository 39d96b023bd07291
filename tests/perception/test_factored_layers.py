"""The factored encoder and head layers (linear map before the neighbour gather, the global feature's term
once per cloud, searches without square roots) give the concatenated forms' outputs and gradients with
the same parameters; the references are those in ``scripts/factored_layers_ab_timing.py``."""

from __future__ import annotations

import numpy as np
import pytest
import torch

from perception.encoder import NeighbourEmbedding, knn_indices
from perception.heads import ArticulationHead, SegmentationHead, _run_with_global
from perception.inference import labels_for_all_points, nearest_labels


@pytest.fixture
def ab(load_script):
    return load_script("factored_layers_ab_timing")


@pytest.mark.parametrize("train", [True, False])
def test_neighbour_embedding_equals_the_edge_tensor_form(ab, train):
    torch.manual_seed(0)
    layer = NeighbourEmbedding(8).train(train)
    with torch.no_grad():  # a non-trivial batch norm
        layer.mlp[1].running_mean.uniform_(-0.5, 0.5)
        layer.mlp[1].running_var.uniform_(0.5, 2.0)
        layer.mlp[1].weight.uniform_(0.5, 1.5)
        layer.mlp[1].bias.uniform_(-0.2, 0.2)
    feat = torch.randn(2, 8, 30, requires_grad=True)
    idx = knn_indices(torch.randn(2, 30, 3), 5)
    out = layer(feat, idx)
    assert out.shape == (2, 8, 30)
    feat_ref = feat.detach().clone().requires_grad_(True)
    ref = ab.concat_neighbour_forward(layer, feat_ref, idx)
    torch.testing.assert_close(out, ref, rtol=1e-5, atol=1e-5)
    out.square().sum().backward()
    weight_grad = layer.mlp[0].weight.grad.clone()
    layer.zero_grad()
    ref.square().sum().backward()
    torch.testing.assert_close(feat.grad, feat_ref.grad, rtol=1e-4, atol=1e-5)
    torch.testing.assert_close(weight_grad, layer.mlp[0].weight.grad, rtol=1e-4, atol=1e-5)


@pytest.mark.parametrize("head_cls,out_dim", [(SegmentationHead, 3), (ArticulationHead, 16)])
def test_heads_equal_the_broadcast_global_form(ab, head_cls, out_dim):
    torch.manual_seed(1)
    head = head_cls(12 + 24, 16, 3 if head_cls is SegmentationHead else 2, 0.0).eval()
    per_point, global_feat = torch.randn(2, 20, 12), torch.randn(2, 24)
    out = _run_with_global(head.mlp, per_point, global_feat)
    assert out.shape == (2, out_dim, 20)
    torch.testing.assert_close(out, ab.concat_run_with_global(head.mlp, per_point, global_feat),
                               rtol=1e-5, atol=1e-5)


def test_the_first_head_layer_keeps_its_bias_when_it_has_one(ab):
    torch.manual_seed(2)
    mlp = torch.nn.Sequential(torch.nn.Conv1d(10, 4, 1, bias=True), torch.nn.ReLU())
    per_point, global_feat = torch.randn(1, 7, 4), torch.randn(1, 6)
    torch.testing.assert_close(_run_with_global(mlp, per_point, global_feat),
                               ab.concat_run_with_global(mlp, per_point, global_feat), rtol=1e-5, atol=1e-6)


def test_knn_finds_the_same_neighbours_as_cdist(ab):
    xyz = torch.rand(3, 200, 3, generator=torch.Generator().manual_seed(3)) * 2 - 1
    mine, ref = knn_indices(xyz, 16), ab.cdist_knn_indices(xyz, 16)
    assert mine.shape == (3, 200, 16)
    assert (mine[..., 0] == torch.arange(200)).all()  # each point is its own nearest
    assert torch.equal(mine.sort(dim=-1).values, ref.sort(dim=-1).values)


def test_knn_on_a_line_by_hand():
    xyz = torch.tensor([[[0.0, 0, 0], [1.0, 0, 0], [3.0, 0, 0], [7.0, 0, 0]]])
    assert knn_indices(xyz, 2)[0].tolist() == [[0, 1], [1, 0], [2, 1], [3, 2]]


def test_labels_of_fed_points_are_their_own_and_others_take_the_nearest(ab):
    rng = np.random.default_rng(4)
    points = rng.uniform(-1, 1, size=(300, 3))
    fed = np.sort(rng.choice(300, size=80, replace=False))
    fed_labels = rng.integers(0, 4, size=80)
    labels = labels_for_all_points(points, fed, fed_labels)
    assert labels.dtype == np.int64 and labels.shape == (300,)
    np.testing.assert_array_equal(labels[fed], fed_labels)
    np.testing.assert_array_equal(labels, ab.cdist_labels_for_all_points(points, fed, fed_labels))


def test_nearest_labels_by_hand():
    ref = np.array([[0.0, 0, 0], [10.0, 0, 0]])
    query = np.array([[4.9, 0, 0], [5.1, 0, 0], [-3.0, 1, 0]])
    assert nearest_labels(query, ref, np.array([7, 9])).tolist() == [7, 9, 7]


def test_the_ab_script_switches_forms_and_restores_the_factored_ones(ab):
    from perception import encoder, heads, inference

    try:
        ab.use_factored(False)
        assert encoder.knn_indices is ab.cdist_knn_indices
        assert heads._run_with_global is ab.concat_run_with_global
        assert inference.labels_for_all_points is ab.cdist_labels_for_all_points
    finally:
        ab.use_factored(True)
    assert encoder.knn_indices is knn_indices and heads._run_with_global is _run_with_global
    assert NeighbourEmbedding.forward is ab.FACTORED["neighbour"]


@pytest.mark.parametrize("argv,message", [(["--rounds", "1"], "--rounds >= 2"),
                                          (["--categories", "nowhere", "--data", "/nonexistent"],
                                           "no dataset for nowhere")])
def test_the_ab_command_line_refuses_bad_arguments(monkeypatch, capsys, argv, message):
    from perception import interleaved_timing

    switched = []
    monkeypatch.setattr("sys.argv", ["ab", *argv])
    with pytest.raises(SystemExit):
        interleaved_timing.main("ab", switched.append, ("a", "b"))
    assert message in capsys.readouterr().err
    assert switched == []  # nothing was timed or switched
