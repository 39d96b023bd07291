"""perception/pointwise.py: the 1x1 convolutions as matrix products give nn.Conv1d's / nn.Conv2d's
outputs and gradients, with the same state_dict."""

from __future__ import annotations

import pytest
import torch
from torch import nn

from perception.pointwise import PointwiseConv1d, PointwiseConv2d


@pytest.mark.parametrize("bias", [True, False])
def test_pointwise_conv1d_matches_conv1d(bias):
    torch.manual_seed(0)
    ref = nn.Conv1d(6, 5, 1, bias=bias)
    mine = PointwiseConv1d(6, 5, bias=bias)
    mine.load_state_dict(ref.state_dict())  # same keys and shapes
    x = torch.randn(3, 6, 40, requires_grad=True)
    x2 = x.detach().clone().requires_grad_(True)
    out_ref, out = ref(x), mine(x2)
    assert out.shape == (3, 5, 40)
    torch.testing.assert_close(out, out_ref, rtol=1e-5, atol=1e-6)
    out_ref.square().sum().backward()
    out.square().sum().backward()
    torch.testing.assert_close(x2.grad, x.grad, rtol=1e-5, atol=1e-5)
    torch.testing.assert_close(mine.weight.grad, ref.weight.grad, rtol=1e-5, atol=1e-5)


@pytest.mark.parametrize("bias", [True, False])
def test_pointwise_conv2d_matches_conv2d(bias):
    torch.manual_seed(1)
    ref = nn.Conv2d(8, 4, 1, bias=bias)
    mine = PointwiseConv2d(8, 4, bias=bias)
    mine.load_state_dict(ref.state_dict())
    x = torch.randn(2, 8, 30, 7)
    torch.testing.assert_close(mine(x), ref(x), rtol=1e-5, atol=1e-6)
    assert set(mine.state_dict()) == set(ref.state_dict())
    assert all(mine.state_dict()[k].shape == v.shape for k, v in ref.state_dict().items())


def test_the_ab_timing_script_switches_between_matrix_product_and_convolution(load_script):
    ab = load_script("pointwise_ab_timing")
    torch.manual_seed(2)
    layer = PointwiseConv1d(4, 3)
    x = torch.randn(1, 4, 10)
    try:
        ab.use_matmul(False)
        assert PointwiseConv1d.forward is nn.Conv1d.forward and PointwiseConv2d.forward is nn.Conv2d.forward
        conv_out = layer(x)
    finally:
        ab.use_matmul(True)
    assert PointwiseConv1d.forward is not nn.Conv1d.forward
    torch.testing.assert_close(layer(x), conv_out, rtol=1e-5, atol=1e-6)
