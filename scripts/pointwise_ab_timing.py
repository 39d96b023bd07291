"""A/B timing of CAPT inference with the pointwise layers as matrix products (``perception/pointwise.py``,
the default) against the same layers as oneDNN 1x1 convolutions (``nn.Conv1d/2d.forward``).

Timed interleaved, in ABBA rounds in one process on the same test clouds, by
:mod:`perception.interleaved_timing` (median ``predict`` and forward-pass times per category).

    .venv/bin/python scripts/pointwise_ab_timing.py --categories laptop oven \
        --json benchmarks/pointwise_ab_timing.json
"""

from __future__ import annotations

from torch import nn

from perception import interleaved_timing, pointwise

MATMUL = (pointwise.PointwiseConv1d.forward, pointwise.PointwiseConv2d.forward)


def use_matmul(matmul: bool) -> None:
    """Switch every pointwise layer between its matrix product and nn.Conv1d/2d's convolution."""
    pointwise.PointwiseConv1d.forward = MATMUL[0] if matmul else nn.Conv1d.forward
    pointwise.PointwiseConv2d.forward = MATMUL[1] if matmul else nn.Conv2d.forward


if __name__ == "__main__":
    interleaved_timing.main(__doc__.splitlines()[0], use_matmul, ("matmul", "conv"))
