"""Do two loss terms pull the shared weights the same way? Gradient alignment of CAPT's loss terms
(a diagnostic for paper Sec. III-B/C: does the motion loss work with the state loss or against it?).

L = [L_seg, L_dir, L_pdir, L_dist, L_s, L_motion] . W trains one network: the PCT encoder and the
articulation branch's hidden layers are shared by every term, and only the branch's last layer has
an output channel per quantity. For a batch, each weighted term w_t * L_t is differentiated alone
with respect to a group of shared parameters, flattened into one vector g_t, and two terms compare
by the cosine of their vectors (-1: opposite, 0: unrelated, +1: the same direction) and by the ratio
of their norms (how hard one pulls next to the other). A step of plain gradient descent on the sum
lowers term a to first order by lr * (|g_a|^2 + g_a . g_b); a negative cosine with a comparable norm
means the other term's step raises term a.

Parameter groups (``PARAMETER_GROUPS``):

- ``encoder``: the PCT encoder (input and neighbour embeddings, offset-attention layers);
- ``articulation_shared``: the articulation branch's hidden layers (every layer but the last);
- ``shared``: the two together, every weight both the state and the motion term reach.

The network is in eval mode (batch-norm running statistics, no dropout) so the result is a function
of the weights and the batch alone. Works on any per-point variant's checkpoint: the motion term is
computed with the given weight even where the variant trained without it (CAPT-plain).
"""

from __future__ import annotations

from collections.abc import Iterable, Mapping, Sequence
from dataclasses import dataclass, replace

import numpy as np
import torch

from perception.config import CaptConfig
from perception.losses import capt_losses
from perception.model import CaptModel

PARAMETER_GROUPS: tuple[str, ...] = ("encoder", "articulation_shared", "shared")
LOSS_TERMS: tuple[str, ...] = ("seg", "dir", "pdir", "dist", "state", "motion")


def group_parameters(model: CaptModel, group: str) -> list[torch.nn.Parameter]:
    """The parameters of ``group`` (one of :data:`PARAMETER_GROUPS`) of a per-point ``model``."""
    if model.art_head is None:
        raise ValueError("gradient alignment needs a per-point variant (capt or capt_plain)")
    layers = list(model.art_head.mlp.children())
    art_shared = [p for layer in layers[:-1] for p in layer.parameters()]
    if group == "encoder":
        return list(model.encoder.parameters())
    if group == "articulation_shared":
        return art_shared
    if group == "shared":
        return list(model.encoder.parameters()) + art_shared
    raise ValueError(f"unknown parameter group {group!r}; expected one of {PARAMETER_GROUPS}")


def term_gradients(model: CaptModel, batch: Mapping[str, torch.Tensor], config: CaptConfig,
                   terms: Sequence[str], motion_weight: float) -> dict[str, dict[str, torch.Tensor]]:
    """Flattened gradient of each weighted term ``w_t * L_t`` on ``batch``, per parameter group:
    ``{term: {group: (P,) tensor}}``. Weights are the config's (``motion_weight`` for the motion term,
    whatever the variant). A term that does not reach a group gives a zero vector."""
    unknown = [t for t in terms if t not in LOSS_TERMS]
    if unknown:
        raise ValueError(f"unknown loss terms {unknown}; expected some of {LOSS_TERMS}")
    weights = replace(config.loss.weights, motion=motion_weight)
    # capt_losses computes the motion term only when its effective weight is positive: score as capt
    scoring = replace(config, model=replace(config.model, variant="capt"),
                      loss=replace(config.loss, weights=replace(weights, motion=max(motion_weight, 1e-12))))
    model.eval()
    out = model(batch["points"])
    losses = capt_losses(out, dict(batch), scoring)
    encoder, art_shared = group_parameters(model, "encoder"), group_parameters(model, "articulation_shared")
    params = encoder + art_shared
    result: dict[str, dict[str, torch.Tensor]] = {}
    for term in terms:
        weighted = getattr(weights, term) * losses[term]
        grads = torch.autograd.grad(weighted, params, retain_graph=True, allow_unused=True)
        flat = [(torch.zeros_like(p) if g is None else g).reshape(-1)
                for g, p in zip(grads, params, strict=True)]
        result[term] = {"encoder": torch.cat(flat[:len(encoder)]),
                        "articulation_shared": torch.cat(flat[len(encoder):]),
                        "shared": torch.cat(flat)}
    return result


def cosine(a: torch.Tensor, b: torch.Tensor) -> float:
    """Cosine of two flat vectors; NaN when either is zero."""
    na, nb = float(a.norm()), float(b.norm())
    if na == 0.0 or nb == 0.0:
        return float("nan")
    return float(torch.dot(a, b)) / (na * nb)


@dataclass(frozen=True)
class Alignment:
    """How ``other`` pulls against ``reference`` on one parameter group, over batches: the mean and
    the share below 0 of the per-batch cosines, the cosine of the gradients summed over batches (the
    direction an epoch's steps take on average), and the mean ratio |g_other| / |g_reference|."""

    reference: str
    other: str
    group: str
    mean_cosine: float
    negative_share: float
    summed_cosine: float
    norm_ratio: float
    batches: int


def alignments(per_batch: Iterable[Mapping[str, Mapping[str, torch.Tensor]]], reference: str,
               others: Sequence[str], groups: Sequence[str] = PARAMETER_GROUPS) -> list[Alignment]:
    """Summarise :func:`term_gradients` results of several batches: ``reference`` against each of
    ``others`` on each of ``groups``."""
    batches = list(per_batch)
    if not batches:
        raise ValueError("no batches to summarise")
    rows = []
    for other in others:
        for g in groups:
            cos = np.array([cosine(b[reference][g], b[other][g]) for b in batches])
            ratio = np.array([float(b[other][g].norm()) / max(float(b[reference][g].norm()), 1e-30)
                              for b in batches])
            summed = cosine(sum(b[reference][g] for b in batches), sum(b[other][g] for b in batches))
            valid = cos[~np.isnan(cos)]
            rows.append(Alignment(reference, other, g,
                                  float(valid.mean()) if len(valid) else float("nan"),
                                  float((valid < 0).mean()) if len(valid) else float("nan"),
                                  summed, float(ratio.mean()), len(batches)))
    return rows
