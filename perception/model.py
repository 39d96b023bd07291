"""The CAPT network (paper Sec. III-A, Fig. 2): PCT encoder + decoder branches, for every variant.

Input: points (B, n, 3) in the normalised object frame (see :mod:`perception.normalisation`).
"""

from __future__ import annotations

from dataclasses import dataclass

import torch
from torch import nn

from perception.config import ModelConfig
from perception.encoder import PCTEncoder
from perception.heads import ArticulationHead, RegressionHead, SegmentationHead, SlotTypeHead


@dataclass
class CaptOutput:
    """Network outputs (normalised frame). Per-point fields are None for ``pct_regression``; ``reg_*``
    fields are None for the voting variants; ``seg_logits`` is None without a segmentation head.

    seg_logits (B, n, n_L); dir (B, n, J, 3) unit; dist (B, n, J) >= 0; pdir (B, n, J, 3) unit;
    state (B, n, J) radians or normalised length; reg_dir (B, J, 3); reg_pivot (B, J, 3); reg_state (B, J);
    slot_type_logits (B, J, 3) over revolute, prismatic, absent (models with ``any`` slots only).
    """

    seg_logits: torch.Tensor | None = None
    dir: torch.Tensor | None = None
    dist: torch.Tensor | None = None
    pdir: torch.Tensor | None = None
    state: torch.Tensor | None = None
    reg_dir: torch.Tensor | None = None
    reg_pivot: torch.Tensor | None = None
    reg_state: torch.Tensor | None = None
    slot_type_logits: torch.Tensor | None = None

    def pivots(self, points: torch.Tensor) -> torch.Tensor:
        """Per-point pivot votes p + dist * pdir, (B, n, J, 3); ``points`` (B, n, 3)."""
        assert self.dist is not None and self.pdir is not None, "per-point outputs needed"
        return points.unsqueeze(2) + self.dist.unsqueeze(-1) * self.pdir


class CaptModel(nn.Module):
    """CAPT / CAPT-plain / PCT-regression network built from a :class:`ModelConfig`."""

    def __init__(self, config: ModelConfig) -> None:
        super().__init__()
        config.validate()
        self.config = config
        self.encoder = PCTEncoder(config.embed_dim, config.knn_k, config.neighbor_layers)
        head_in = self.encoder.point_dim + self.encoder.global_dim
        self.seg_head = (SegmentationHead(head_in, config.head_dim, config.max_parts, config.dropout)
                         if config.has_segmentation else None)
        if config.per_point:
            self.art_head: nn.Module | None = ArticulationHead(head_in, config.head_dim, config.max_joints,
                                                               config.dropout)
            self.reg_head: nn.Module | None = None
        else:
            self.art_head = None
            self.reg_head = RegressionHead(self.encoder.global_dim, config.head_dim, config.max_joints,
                                           config.dropout)
        self.slot_type_head = (SlotTypeHead(self.encoder.global_dim, config.head_dim, config.max_joints,
                                            config.dropout) if config.predicts_joint_types else None)

    def forward(self, points: torch.Tensor) -> CaptOutput:
        """``points`` (B, n, 3) float, normalised object frame -> :class:`CaptOutput`."""
        if points.dim() != 3 or points.shape[-1] != 3:
            raise ValueError(f"points must be (B, n, 3), got {tuple(points.shape)}")
        per_point, global_feat = self.encoder(points)
        out = CaptOutput()
        if self.seg_head is not None:
            out.seg_logits = self.seg_head(per_point, global_feat)
        if self.art_head is not None:
            out.dir, out.dist, out.pdir, out.state = self.art_head(per_point, global_feat)
        if self.reg_head is not None:
            out.reg_dir, out.reg_pivot, out.reg_state = self.reg_head(global_feat)
        if self.slot_type_head is not None:
            out.slot_type_logits = self.slot_type_head(global_feat)
        return out
