"""CAPT training losses (paper Sec. III-B "Motion Loss" and III-C "Total Loss").

L = [L_seg, L_dir, L_pdir, L_dist, L_s, L_motion] . W, all in the normalised object frame.

Batch keys read (B samples, n points, J joint slots; see :mod:`perception.data`):
``points`` (B,n,3); ``part_labels`` (B,n) long, -1 = ignore; ``joint_dirs`` (B,J,3) unit;
``joint_pivots`` (B,J,3); ``joint_states`` (B,J) radians / normalised length; ``joint_types`` (B,J)
long 0 revolute, 1 prismatic; ``joint_mask`` (B,J) bool; ``joint_child_part`` (B,J) long;
``dist`` (B,n,J) and ``pdir`` (B,n,J,3) per-point targets.

Averaging (documented choices):
- Per-point articulation terms (dir, pdir, dist, state) are averaged over **all object points** of a
  sample for each joint, because every point votes for every joint at inference (the paper's coarse
  vote sums over all n points), then averaged over the (sample, joint) pairs present.
- The motion loss uses the child part P_k of each joint (points whose ground-truth label is the joint's
  child link), moves every point p_i of P_k about its *own* predicted axis (direction dir_i, pivot
  p_i + dist_i * pdir_i) and about the true axis, and averages ||p'_i - p^'_i|| over P_k (the paper's
  sum_i / n_k), then over present joints. Per-point axes give every point's prediction a gradient.
- Revolute joints rotate by ``motion_angle`` (pi/2). Prismatic joints translate by ``motion_distance``
  along the axis; their pdir/dist targets are meaningless (a prismatic axis has no position) and are
  masked out of L_pdir and L_dist.
- L_dist uses |d_hat - d| per point (the paper's "L2" norm of a scalar difference).
- Joints or parts absent in a sample contribute zero; a term with nothing to average is 0.
- ``pct_regression``: L_dir on the regressed direction, a pivot term (distance from the regressed pivot
  to the true axis line, revolute only, weighted by W.dist) and L_s; no motion loss.
"""

from __future__ import annotations

import torch
import torch.nn.functional as F

from perception.config import CaptConfig
from perception.geometry import point_line_distance, rotate_about_axis
from perception.model import CaptOutput

REVOLUTE, PRISMATIC = 0, 1


def masked_mean(values: torch.Tensor, mask: torch.Tensor) -> torch.Tensor:
    """Mean of ``values`` where ``mask``; 0 (keeping the graph) if the mask is empty."""
    m = mask.to(values.dtype)
    return (values * m).sum() / m.sum().clamp_min(1.0)


def _per_joint_point_mean(values: torch.Tensor, point_mask: torch.Tensor
                          ) -> tuple[torch.Tensor, torch.Tensor]:
    """values (B,n,J), point_mask (B,n,J) -> per (b,k) mean (B,J) and whether it had points (B,J)."""
    m = point_mask.to(values.dtype)
    count = m.sum(dim=1)
    return (values * m).sum(dim=1) / count.clamp_min(1.0), count > 0


def segmentation_loss(logits: torch.Tensor, labels: torch.Tensor) -> torch.Tensor:
    """Cross-entropy averaged over labelled points; logits (B,n,n_L), labels (B,n) with -1 ignored."""
    valid = labels >= 0
    if not bool(valid.any()):
        return logits.sum() * 0.0
    return F.cross_entropy(logits[valid], labels[valid])


def cosine_loss(pred: torch.Tensor, target: torch.Tensor) -> torch.Tensor:
    """1 - cosine similarity along the last dim."""
    return 1.0 - F.cosine_similarity(pred, target, dim=-1, eps=1e-8)


def motion_loss(points: torch.Tensor, out: CaptOutput, batch: dict[str, torch.Tensor],
                angle: float, distance: float) -> torch.Tensor:
    """Mean distance between the child part moved about the predicted and the true axes (see module doc)."""
    labels, types = batch["part_labels"], batch["joint_types"]
    child = (labels.unsqueeze(-1) == batch["joint_child_part"].unsqueeze(1)) & (labels.unsqueeze(-1) >= 0)
    p = points.unsqueeze(2).expand(-1, -1, types.shape[1], -1)  # (B,n,J,3)
    u_true = batch["joint_dirs"].unsqueeze(1).expand_as(p)
    q_true = batch["joint_pivots"].unsqueeze(1).expand_as(p)
    assert out.dir is not None
    rot_err = (rotate_about_axis(p, out.dir, out.pivots(points), angle)
               - rotate_about_axis(p, u_true, q_true, angle)).norm(dim=-1)
    trans_err = distance * (out.dir - u_true).norm(dim=-1)
    err = torch.where((types == PRISMATIC).unsqueeze(1), trans_err, rot_err)
    per_joint, has_points = _per_joint_point_mean(err, child)
    return masked_mean(per_joint, batch["joint_mask"] & has_points)


def capt_losses(out: CaptOutput, batch: dict[str, torch.Tensor], config: CaptConfig
                ) -> dict[str, torch.Tensor]:
    """Named loss components and their weighted sum under key ``"total"``."""
    w = config.effective_loss_weights()
    points, labels = batch["points"], batch["part_labels"]
    jmask, types = batch["joint_mask"], batch["joint_types"]
    revolute = jmask & (types == REVOLUTE)
    zero = points.sum() * 0.0
    parts: dict[str, torch.Tensor] = {}
    parts["seg"] = segmentation_loss(out.seg_logits, labels) if out.seg_logits is not None else zero

    if out.dir is not None:
        assert out.dist is not None and out.pdir is not None and out.state is not None
        obj = (labels >= 0).unsqueeze(-1).expand_as(out.dist)
        u = batch["joint_dirs"].unsqueeze(1)
        terms = {
            "dir": cosine_loss(out.dir, u),
            "pdir": cosine_loss(out.pdir, batch["pdir"]),
            "dist": (out.dist - batch["dist"]).abs(),
            "state": (out.state - batch["joint_states"].unsqueeze(1)).abs(),
        }
        for name, values in terms.items():
            per_joint, has_points = _per_joint_point_mean(values, obj)
            joints = revolute if name in ("pdir", "dist") else jmask
            parts[name] = masked_mean(per_joint, joints & has_points)
        if w.motion > 0.0:
            parts["motion"] = motion_loss(points, out, batch, config.loss.motion_angle,
                                          config.loss.motion_distance)
        else:
            parts["motion"] = zero
        total = (w.seg * parts["seg"] + w.dir * parts["dir"] + w.pdir * parts["pdir"]
                 + w.dist * parts["dist"] + w.state * parts["state"] + w.motion * parts["motion"])
    else:
        assert out.reg_dir is not None and out.reg_pivot is not None and out.reg_state is not None
        parts["dir"] = masked_mean(cosine_loss(out.reg_dir, batch["joint_dirs"]), jmask)
        parts["pivot"] = masked_mean(
            point_line_distance(out.reg_pivot, batch["joint_dirs"], batch["joint_pivots"]), revolute)
        parts["state"] = masked_mean((out.reg_state - batch["joint_states"]).abs(), jmask)
        total = (w.seg * parts["seg"] + w.dir * parts["dir"] + w.dist * parts["pivot"]
                 + w.state * parts["state"])
    if out.slot_type_logits is not None:
        parts["slot_type"] = slot_type_loss(out.slot_type_logits, types, jmask)
        total = total + w.slot_type * parts["slot_type"]
    parts["total"] = total
    return parts


def slot_type_targets(types: torch.Tensor, mask: torch.Tensor) -> torch.Tensor:
    """(B, J) class of each slot in :data:`perception.config.SLOT_TYPES`: its joint type where ``mask``
    holds a joint, 2 (absent) elsewhere."""
    return torch.where(mask, types, torch.full_like(types, 2))


def slot_type_loss(logits: torch.Tensor, types: torch.Tensor, mask: torch.Tensor) -> torch.Tensor:
    """Cross-entropy of the slot-type logits (B, J, 3) against :func:`slot_type_targets`."""
    return F.cross_entropy(logits.reshape(-1, 3), slot_type_targets(types, mask).reshape(-1))
