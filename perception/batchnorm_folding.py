"""Batch-norm folding for inference: each (linear layer, BatchNorm) pair of a trained model becomes one
linear layer with the normalisation's scale and shift in its weights.

In eval mode a BatchNorm is the per-channel affine map y = a x + b with a = gamma / sqrt(var + eps) and
b = beta - a mean (running statistics), so it folds into the layer before it: W' = a W, b' = a b_W + b.
The folded model computes the same function up to float rounding and skips one pass over every
activation it normalised. PyTorch's own ``fuse_conv_bn_eval`` / ``fuse_linear_bn_eval`` do the
arithmetic; this module only finds the pairs: ``nn.Sequential`` children of the form (PointwiseConv1d
or Linear, BatchNorm1d) and the offset-attention layers' (``trans``, ``norm``), the BatchNorm replaced
by ``Identity``. The encoder's neighbour embedding (a 2d
pair whose weights it reads by hand) folds its own normalisation in eval mode
(:class:`perception.encoder.NeighbourEmbedding`).
"""

from __future__ import annotations

import copy

from torch import nn
from torch.nn.utils.fusion import fuse_conv_bn_eval, fuse_linear_bn_eval

from perception.encoder import OffsetAttention
from perception.pointwise import PointwiseConv1d


def fold_batchnorm(model: nn.Module) -> nn.Module:
    """A copy of ``model`` in eval mode with every foldable (linear, BatchNorm1d) pair folded into the
    linear layer; ``model`` itself is not changed (it may still be trained)."""
    folded = copy.deepcopy(model).eval()
    for module in folded.modules():
        if isinstance(module, OffsetAttention) and isinstance(module.norm, nn.BatchNorm1d):
            module.trans = fuse_conv_bn_eval(module.trans, module.norm)
            module.norm = nn.Identity()
        if not isinstance(module, nn.Sequential):
            continue
        for i in range(len(module) - 1):
            layer, norm = module[i], module[i + 1]
            if not isinstance(norm, nn.BatchNorm1d):
                continue
            if isinstance(layer, PointwiseConv1d):
                module[i] = fuse_conv_bn_eval(layer, norm)
            elif isinstance(layer, nn.Linear):
                module[i] = fuse_linear_bn_eval(layer, norm)
            else:
                continue
            module[i + 1] = nn.Identity()
    return folded

