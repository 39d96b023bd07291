"""Shared per-point linear layers (the 1x1 convolutions of PCT and of CAPT's heads) as matrix products.

``PointwiseConv1d`` / ``PointwiseConv2d`` are ``nn.Conv1d`` / ``nn.Conv2d`` with kernel size 1: the same
parameters, the same ``state_dict`` keys and shapes (so checkpoints load either way), the same outputs up
to float rounding. Only ``forward`` differs: one matrix product over the channel dim instead of a
convolution call, which oneDNN runs more slowly than the equivalent GEMM on this project's 2-core CPU.
The gain is small: interleaved A/B on the four shipped models (``scripts/pointwise_ab_timing.py``,
session 29) made the forward pass 0.3-2.5 ms faster (24-33 ms), within the machine's noise for a
whole ``predict`` call. Since session 30 the encoder's neighbour embedding only keeps its weights in a
``PointwiseConv2d`` (so its ``state_dict`` is unchanged) and multiplies them itself before the
neighbour gather (:class:`perception.encoder.NeighbourEmbedding`); the 2d layer's ``forward`` is not
called by the model any more.
"""

from __future__ import annotations

import torch
from torch import nn


class PointwiseConv1d(nn.Conv1d):
    """(B, C_in, n) -> (B, C_out, n): a shared linear map applied at every point."""

    def __init__(self, in_channels: int, out_channels: int, bias: bool = True) -> None:
        super().__init__(in_channels, out_channels, kernel_size=1, bias=bias)

    def forward(self, x: torch.Tensor) -> torch.Tensor:
        y = torch.matmul(self.weight[:, :, 0], x)
        return y if self.bias is None else y + self.bias[:, None]


class PointwiseConv2d(nn.Conv2d):
    """(B, C_in, n, k) -> (B, C_out, n, k): a shared linear map applied at every (point, neighbour)."""

    def __init__(self, in_channels: int, out_channels: int, bias: bool = True) -> None:
        super().__init__(in_channels, out_channels, kernel_size=1, bias=bias)

    def forward(self, x: torch.Tensor) -> torch.Tensor:
        b, _, n, k = x.shape
        y = torch.matmul(self.weight[:, :, 0, 0], x.reshape(b, x.shape[1], n * k)).reshape(b, -1, n, k)
        return y if self.bias is None else y + self.bias[:, None, None]
