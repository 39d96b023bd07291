"""Configuration of CAPT (paper Sec. III): model variant and sizes, loss weights W, double-voting window.

Every dataclass mirrors a YAML mapping one to one (see :mod:`capt_common.typed_yaml`); defaults live
here. Variants:

- ``capt``: PCT encoder, segmentation + per-point articulation branches, motion loss, double voting.
- ``capt_plain``: the same network without motion loss (its weight is forced to 0) and without double
  voting (the coarse mean is the answer).
- ``pct_regression``: the paper's "PCT" baseline: same encoder, max+mean pooled global feature, one MLP
  that regresses per joint direction (3), pivot (3) and state (1). No motion loss, no voting; a
  segmentation head only when ``regression_seg_head`` is true (the paper's PCT row has none).

A joint slot's type is fixed by the category (``revolute``, ``prismatic``) or ``any``: the network
then predicts the slot's type (revolute, prismatic or absent) from its global feature, so one model
serves objects of every category without being told which (the cross-category model,
``configs/perception/capt_cross_category.yaml``).
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field, replace
from typing import Literal

from capt_common.typed_yaml import require
from perception.corruption import Corruption

Variant = Literal["capt", "capt_plain", "pct_regression"]
JointType = Literal["revolute", "prismatic", "any"]
JOINT_TYPE_CODES: dict[str, int] = {"revolute": 0, "prismatic": 1}
SLOT_TYPES = ("revolute", "prismatic", "absent")
"""The classes a slot-type head predicts, in logit order; a slot whose joint is absent is class 2."""


@dataclass(frozen=True)
class ModelConfig:
    """Network shape. ``embed_dim`` is d_e: each of the four offset-attention layers is d_e wide and
    their concatenation gives 4*d_e per-point features. ``max_parts`` (n_L) and ``max_joints`` (n_J)
    size the output channels for the category; ``joint_types`` names the type of every joint slot
    (``any``: predicted per object, see the module docstring)."""

    variant: Variant = "capt"
    num_points: int = 1024
    embed_dim: int = 128
    knn_k: int = 16
    neighbor_layers: int = 1
    head_dim: int = 256
    max_parts: int = 2
    max_joints: int = 1
    joint_types: tuple[JointType, ...] = ("revolute",)
    joint_child_parts: tuple[int, ...] = (1,)
    dropout: float = 0.1
    regression_seg_head: bool = False

    def validate(self) -> None:
        require(self.num_points >= 32, f"model.num_points must be >= 32, got {self.num_points}")
        require(self.embed_dim >= 4 and self.embed_dim % 4 == 0,
                f"model.embed_dim must be a positive multiple of 4, got {self.embed_dim}")
        require(1 <= self.knn_k <= self.num_points,
                f"model.knn_k must be in [1, num_points], got {self.knn_k}")
        require(0 <= self.neighbor_layers <= 4, "model.neighbor_layers must be in [0, 4]")
        require(self.head_dim >= 8, "model.head_dim must be >= 8")
        require(self.max_parts >= 1, "model.max_parts must be >= 1")
        require(self.max_joints >= 1, "model.max_joints must be >= 1")
        require(len(self.joint_types) == self.max_joints,
                f"model.joint_types has {len(self.joint_types)} entries but max_joints is {self.max_joints}")
        require(len(self.joint_child_parts) == self.max_joints and
                all(0 <= c < self.max_parts for c in self.joint_child_parts),
                f"model.joint_child_parts needs {self.max_joints} part indices in [0, {self.max_parts})")
        require(0.0 <= self.dropout < 1.0, "model.dropout must be in [0, 1)")

    @property
    def has_segmentation(self) -> bool:
        """Whether the network predicts part labels."""
        return self.variant != "pct_regression" or self.regression_seg_head

    @property
    def predicts_joint_types(self) -> bool:
        """Whether a slot-type head predicts each slot's type (some slot is ``any``)."""
        return "any" in self.joint_types

    @property
    def per_point(self) -> bool:
        """Whether the network predicts per-point articulation (and so needs voting)."""
        return self.variant != "pct_regression"


@dataclass(frozen=True)
class LossWeights:
    """The paper's W = [seg, dir, pdir, dist, state, motion] = [1, 1, 1, 1, 1, 0.1], plus the weight of
    the slot-type cross-entropy (used only by a model with ``any`` slots)."""

    seg: float = 1.0
    dir: float = 1.0
    pdir: float = 1.0
    dist: float = 1.0
    state: float = 1.0
    motion: float = 0.1
    slot_type: float = 1.0

    def validate(self) -> None:
        for name in ("seg", "dir", "pdir", "dist", "state", "motion", "slot_type"):
            require(getattr(self, name) >= 0.0, f"loss.weights.{name} must be >= 0")


@dataclass(frozen=True)
class LossConfig:
    """Loss weights plus the motion loss's move: ``motion_angle`` radians for revolute joints (paper:
    pi/2), ``motion_distance`` normalised-frame units along the axis for prismatic joints."""

    weights: LossWeights = field(default_factory=LossWeights)
    motion_angle: float = math.pi / 2
    motion_distance: float = 0.5

    def validate(self) -> None:
        self.weights.validate()
        require(0.0 < self.motion_angle <= math.pi, "loss.motion_angle must be in (0, pi]")
        require(self.motion_distance > 0.0, "loss.motion_distance must be > 0")


@dataclass(frozen=True)
class VotingConfig:
    """Double voting: fine voting keeps points whose distance to the coarse axis lies in
    [w0, w1] x median distance. ``grid_w0``/``grid_w1`` are the candidates ``choose_voting_window``
    searches on validation data; ``min_points`` is the smallest fine set used (else coarse)."""

    w0: float = 0.5
    w1: float = 2.0
    min_points: int = 8
    grid_w0: tuple[float, ...] = (0.0, 0.25, 0.5, 0.75, 1.0)
    grid_w1: tuple[float, ...] = (1.0, 1.25, 1.5, 2.0, 3.0, 1e9)

    def validate(self) -> None:
        require(0.0 <= self.w0 < self.w1, f"voting needs 0 <= w0 < w1, got w0={self.w0}, w1={self.w1}")
        require(self.min_points >= 1, "voting.min_points must be >= 1")
        require(len(self.grid_w0) > 0 and len(self.grid_w1) > 0, "voting grids must not be empty")


@dataclass(frozen=True)
class CaptConfig:
    """Everything that defines a trained CAPT estimator: network, loss and voting."""

    model: ModelConfig = field(default_factory=ModelConfig)
    loss: LossConfig = field(default_factory=LossConfig)
    voting: VotingConfig = field(default_factory=VotingConfig)

    def validate(self) -> None:
        self.model.validate()
        self.loss.validate()
        self.voting.validate()

    @property
    def double_voting(self) -> bool:
        """Only full CAPT votes twice; CAPT-plain uses the coarse mean."""
        return self.model.variant == "capt"

    def effective_loss_weights(self) -> LossWeights:
        """W as used in training: the motion weight is 0 for every variant but ``capt``."""
        w = self.loss.weights
        if self.model.variant != "capt":
            w = replace(w, motion=0.0)
        if not self.model.has_segmentation:
            w = replace(w, seg=0.0)
        return w


@dataclass(frozen=True)
class TrainConfig:
    """One training run. ``device`` is "auto" (CUDA when present), "cpu" or "cuda[:i]"; AMP is used on
    CUDA only. ``max_*_samples`` cap a split (None: all) for quick runs. ``rotation_augmentation``:
    ``so3`` is the paper's (rotation about x, y and z); ``yaw`` rotates about +z only, for clouds in a
    world frame with known up direction (what a calibrated robot camera gives). ``val_pose``: the
    validation clouds (best epoch, double-voting window) as stored (``world``) or each in a fixed
    seeded rigid pose (``yaw``, ``so3``; :func:`perception.data.posed_sample`), to match the poses
    the model will be scored in (``capt evaluate --test-pose``). ``sensor_noise``: Gaussian jitter
    (metres) and stray points (a fraction of the cloud's points, labelled with their nearest point's
    part) added to every augmented training cloud, a new draw every epoch
    (:mod:`perception.corruption`); none by default, as in the paper."""

    model: CaptConfig = field(default_factory=CaptConfig)
    epochs: int = 50
    batch_size: int = 16
    lr: float = 1e-3
    weight_decay: float = 1e-4
    seed: int = 0
    num_workers: int = 0
    device: str = "auto"
    amp: bool = True
    grad_clip: float = 1.0
    augment: bool = True
    rotation_augmentation: Literal["so3", "yaw"] = "so3"
    val_pose: Literal["world", "yaw", "so3"] = "world"
    sensor_noise: Corruption = field(default_factory=Corruption)
    train_split: str = "train"
    val_split: str = "val"
    max_train_samples: int | None = None
    max_val_samples: int | None = None
    progress: bool = True

    def validate(self) -> None:
        self.model.validate()
        require(self.epochs >= 1, "epochs must be >= 1")
        require(self.batch_size >= 1, "batch_size must be >= 1")
        require(self.lr > 0.0, "lr must be > 0")
        require(self.seed >= 0, f"seed must be >= 0, got {self.seed}")
        require(self.weight_decay >= 0.0, "weight_decay must be >= 0")
        require(self.num_workers >= 0, "num_workers must be >= 0")
        require(self.device == "auto" or self.device == "cpu" or self.device.startswith("cuda"),
                f"device must be auto, cpu or cuda[:i], got {self.device!r}")
        require(self.grad_clip >= 0.0, "grad_clip must be >= 0 (0 disables clipping)")
