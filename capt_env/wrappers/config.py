"""Typed configs of the perception wrapper and of object isolation (YAML via capt_common.typed_yaml)."""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import Literal

from capt_common.typed_yaml import require
from capt_env.wrappers.estimate_fusion import FusionConfig
from capt_env.wrappers.refiners import REFINER_NAMES, RefinerName, RefinerSettings, check_refiner_names

Source = Literal["oracle", "noisy_oracle", "capt_raw", "capt"]
CAPT_SOURCES: tuple[str, ...] = ("capt_raw", "capt")
"""The sources that run the CAPT network on the object's points (and need a checkpoint)."""
IsolationMode = Literal["segmentation", "geometric"]
ObsFormat = Literal["flat", "dict"]
NoiseModel = Literal["gaussian", "fixed_offset"]


@dataclass(frozen=True)
class IsolationConfig:
    """How object points are cut from a world-frame cloud (metres, world frame).

    ``mode``: ``segmentation`` keeps points with part label >= 0 (simulation only); ``geometric``
    uses no labels: table plane removal by RANSAC (``plane_iterations`` hypotheses, inlier band
    ``plane_threshold``, points up to ``plane_margin`` above the plane are dropped too), a
    workspace crop to the box ``workspace_min``..``workspace_max``, removal of points within
    ``robot_margin`` of the robot's collision shapes, and statistical outlier removal (mean distance
    to the ``outlier_k`` nearest neighbours above mean + ``outlier_std`` * std is dropped).
    ``seed`` seeds RANSAC.
    """

    mode: IsolationMode = "segmentation"
    plane_iterations: int = 200
    plane_threshold: float = 0.004
    plane_margin: float = 0.002
    workspace_min: tuple[float, float, float] = (-0.45, -0.6, -0.05)
    workspace_max: tuple[float, float, float] = (0.8, 0.6, 1.2)
    robot_margin: float = 0.01
    outlier_k: int = 8
    outlier_std: float = 3.0
    seed: int = 0

    def validate(self) -> None:
        require(self.plane_iterations >= 1, "isolation.plane_iterations must be >= 1")
        require(self.plane_threshold > 0, "isolation.plane_threshold must be > 0 (metres)")
        require(self.plane_margin >= 0, "isolation.plane_margin must be >= 0 (metres)")
        require(all(lo < hi for lo, hi in zip(self.workspace_min, self.workspace_max, strict=True)),
                "isolation.workspace_min must be below workspace_max on every axis")
        require(self.robot_margin >= 0, "isolation.robot_margin must be >= 0 (metres)")
        require(self.outlier_k >= 1, "isolation.outlier_k must be >= 1")
        require(self.outlier_std > 0, "isolation.outlier_std must be > 0")


@dataclass(frozen=True)
class NoiseConfig:
    """Noise of the ``noisy_oracle`` source, by ``model``:

    - ``gaussian`` (redrawn at every estimate): the axis direction is tilted by an angle drawn from
      N(0, ``direction_rad``) (radians) about a random perpendicular axis; pivot and grasp point get
      isotropic Gaussian offsets with per-axis std ``pivot_m`` / ``grasp_m`` (metres); the state gets
      N(0, ``state``) (radians or metres).
    - ``fixed_offset`` (drawn once per episode, then held): an estimator with a consistent error of
      exactly the given sizes. The direction is tilted by exactly ``direction_rad`` about a random
      perpendicular axis; the axis line is moved ``pivot_m`` (metres) off the true one, in a random
      direction perpendicular to it (the line distance is ``pivot_m`` when the tilt is zero); the
      state is off by ``state`` with a random sign; the grasp point by ``grasp_m`` in a random
      direction. Only the directions and signs are random, seeded per episode.

    ``grasp_outward_m`` is a constant bias in both models: the grasp point moves that far (metres)
    along the part's opening direction at it (revolute: along the radius from the axis; prismatic:
    along the axis), like an estimator whose grasp-point convention differs from the ground truth's
    (CAPT puts a laptop's at the outer band of its lip's points, about 1.2 cm beyond the lip's
    centre)."""

    direction_rad: float = 0.05
    pivot_m: float = 0.01
    state: float = 0.02
    grasp_m: float = 0.005
    grasp_outward_m: float = 0.0
    model: NoiseModel = "gaussian"

    def validate(self) -> None:
        for key in ("direction_rad", "pivot_m", "state", "grasp_m", "grasp_outward_m"):
            require(getattr(self, key) >= 0, f"noise.{key} must be >= 0, got {getattr(self, key)}")
        require(self.direction_rad <= 3.15, "noise.direction_rad must be <= pi")


@dataclass(frozen=True)
class PerceptionWrapperConfig:
    """What :class:`~capt_env.wrappers.perception_wrapper.CaptObservationWrapper` does.

    ``source``: ``oracle`` (ground truth from info), ``noisy_oracle`` (ground truth + ``noise``),
    ``capt_raw`` (the CAPT ``checkpoint``'s own estimate: the network with double voting, no
    geometric refiners, no fusion) or ``capt`` (that estimate refined and fused over the episode);
    the checkpoint is loaded lazily on first use. The stages are listed in
    :mod:`~capt_env.wrappers.estimate_pipeline`. Perception runs on reset and then every
    ``every_k_steps`` steps; in between the last estimate is repeated. ``isolation`` selects the
    object points fed to CAPT, downsampled to ``num_points``. ``obs_format``: ``flat`` (Box) or
    ``dict``. ``seed`` seeds noise and downsampling.

    ``capt`` only: ``refiners`` names the geometric refiners that run (any order; they run in the
    pipeline's order, :data:`~capt_env.wrappers.refiners.REFINER_NAMES`; default all, ``[]`` none),
    ``refiner_settings`` holds each refiner's config (:class:`~capt_env.wrappers.refiners.RefinerSettings`,
    whose defaults are the only ones) and ``fusion`` the fusion of successive looks.
    """

    source: Source = "oracle"
    checkpoint: str | None = None
    every_k_steps: int = 1
    isolation: IsolationConfig = field(default_factory=IsolationConfig)
    num_points: int = 1024
    noise: NoiseConfig = field(default_factory=NoiseConfig)
    obs_format: ObsFormat = "flat"
    seed: int = 0
    refiners: tuple[RefinerName, ...] = REFINER_NAMES
    refiner_settings: RefinerSettings = field(default_factory=RefinerSettings)
    fusion: FusionConfig = field(default_factory=FusionConfig)

    @property
    def reads_points(self) -> bool:
        """Whether the source reads the object's points (needs ``obs_mode="pointcloud"``)."""
        return self.source in CAPT_SOURCES

    def validate(self) -> None:
        require(self.every_k_steps >= 1, f"every_k_steps must be >= 1, got {self.every_k_steps}")
        require(self.num_points >= 32, f"num_points must be >= 32, got {self.num_points}")
        if self.source in CAPT_SOURCES:
            require(self.checkpoint is not None, f"source '{self.source}' needs a checkpoint path")
        check_refiner_names(self.refiners)
        self.isolation.validate()
        self.noise.validate()
        self.refiner_settings.validate()
        self.fusion.validate()
