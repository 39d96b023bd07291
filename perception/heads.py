"""CAPT decoder branches (paper Sec. III-A, Fig. 2): segmentation branch and per-point articulation
branch, plus the direct-regression head of the paper's PCT baseline.

Per-point heads read [per-point feature, broadcast global feature]. Output channels are sized for the
category's n_L parts and n_J joints; unused slots are simply ignored by the loss (masks).
"""

from __future__ import annotations

import torch
import torch.nn.functional as F
from torch import nn

from perception.pointwise import PointwiseConv1d


def _pointwise_mlp(in_dim: int, hidden: int, out_dim: int, dropout: float) -> nn.Sequential:
    return nn.Sequential(
        PointwiseConv1d(in_dim, hidden, bias=False), nn.BatchNorm1d(hidden), nn.ReLU(inplace=True),
        nn.Dropout(dropout),
        PointwiseConv1d(hidden, hidden // 2, bias=False), nn.BatchNorm1d(hidden // 2), nn.ReLU(inplace=True),
        PointwiseConv1d(hidden // 2, out_dim),
    )


def _run_with_global(mlp: nn.Sequential, per_point: torch.Tensor, global_feat: torch.Tensor) -> torch.Tensor:
    """``mlp`` applied to [per_point, global_feat broadcast to every point]: (B, n, C), (B, G) -> (B, out, n).

    The first layer's W = [W_p, W_g] is split so the global term W_g g is computed once per cloud and
    added to W_p p at every point, instead of multiplying the broadcast (G, n) copy (G = 2C, so two
    thirds of that layer's products); the same result up to float rounding, the same parameters.
    """
    first, *rest = mlp
    w = first.weight[:, :, 0]
    c = per_point.shape[-1]
    y = torch.matmul(w[:, :c], per_point.transpose(1, 2)) + torch.matmul(w[:, c:], global_feat.unsqueeze(-1))
    if first.bias is not None:
        y = y + first.bias[:, None]
    for layer in rest:
        y = layer(y)
    return y


class SegmentationHead(nn.Module):
    """n_L part logits per point: (B, n, n_L)."""

    def __init__(self, in_dim: int, hidden: int, num_parts: int, dropout: float) -> None:
        super().__init__()
        self.mlp = _pointwise_mlp(in_dim, hidden, num_parts, dropout)

    def forward(self, per_point: torch.Tensor, global_feat: torch.Tensor) -> torch.Tensor:
        return _run_with_global(self.mlp, per_point, global_feat).transpose(1, 2)


class ArticulationHead(nn.Module):
    """Per point p and joint k: direction (3, unit), distance to the axis (1, >= 0 via softplus),
    unit direction from p to the axis (3), state (1). Shapes (B, n, J, 3), (B, n, J), (B, n, J, 3),
    (B, n, J)."""

    def __init__(self, in_dim: int, hidden: int, num_joints: int, dropout: float) -> None:
        super().__init__()
        self.num_joints = num_joints
        self.mlp = _pointwise_mlp(in_dim, hidden, 8 * num_joints, dropout)

    def forward(self, per_point: torch.Tensor, global_feat: torch.Tensor
                ) -> tuple[torch.Tensor, torch.Tensor, torch.Tensor, torch.Tensor]:
        raw = _run_with_global(self.mlp, per_point, global_feat).transpose(1, 2)
        raw = raw.reshape(*raw.shape[:2], self.num_joints, 8)
        direction = F.normalize(raw[..., 0:3], dim=-1, eps=1e-6)
        dist = F.softplus(raw[..., 3])
        pdir = F.normalize(raw[..., 4:7], dim=-1, eps=1e-6)
        return direction, dist, pdir, raw[..., 7]


class RegressionHead(nn.Module):
    """PCT baseline: global feature -> per joint direction (3, unit), pivot (3), state (1)."""

    def __init__(self, in_dim: int, hidden: int, num_joints: int, dropout: float) -> None:
        super().__init__()
        self.num_joints = num_joints
        self.mlp = nn.Sequential(
            nn.Linear(in_dim, hidden, bias=False), nn.BatchNorm1d(hidden), nn.ReLU(inplace=True),
            nn.Dropout(dropout),
            nn.Linear(hidden, hidden // 2, bias=False), nn.BatchNorm1d(hidden // 2), nn.ReLU(inplace=True),
            nn.Linear(hidden // 2, 7 * num_joints),
        )

    def forward(self, global_feat: torch.Tensor) -> tuple[torch.Tensor, torch.Tensor, torch.Tensor]:
        raw = self.mlp(global_feat).reshape(-1, self.num_joints, 7)
        return F.normalize(raw[..., 0:3], dim=-1, eps=1e-6), raw[..., 3:6], raw[..., 6]


class SlotTypeHead(nn.Module):
    """Cross-category slots: global feature -> per joint slot logits over :data:`perception.config.
    SLOT_TYPES` (revolute, prismatic, absent), (B, J, 3). Which joints an object has is a property of
    the whole object, so it is read from the pooled feature, not voted per point."""

    def __init__(self, in_dim: int, hidden: int, num_joints: int, dropout: float) -> None:
        super().__init__()
        self.num_joints = num_joints
        self.mlp = nn.Sequential(
            nn.Linear(in_dim, hidden, bias=False), nn.BatchNorm1d(hidden), nn.ReLU(inplace=True),
            nn.Dropout(dropout), nn.Linear(hidden, 3 * num_joints),
        )

    def forward(self, global_feat: torch.Tensor) -> torch.Tensor:
        return self.mlp(global_feat).reshape(-1, self.num_joints, 3)
