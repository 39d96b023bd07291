"""Typed configs of the perception wrapper and of object isolation (YAML via capt_common.typed_yaml)."""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import Literal

from capt_common.typed_yaml import require

Source = Literal["oracle", "noisy_oracle", "capt"]
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

    ``source``: ``oracle`` (ground truth from info), ``noisy_oracle`` (ground truth + ``noise``) or
    ``capt`` (a CAPT ``checkpoint``, loaded lazily on first use). Perception runs on reset and then
    every ``every_k_steps`` steps; in between the last estimate is repeated. ``isolation`` selects the
    object points fed to CAPT, downsampled to ``num_points``. ``obs_format``: ``flat`` (Box) or
    ``dict``. ``seed`` seeds noise and downsampling. ``hinge_on_part_edge`` (``capt`` only): put a
    revolute estimate's line on the edge of the flat moving part away from the grasp point, in the
    part's plane, when CAPT's own line is more than 6 cm off that edge, and turn the direction into
    the part's plane (``moving_part_geometry.hinge_on_edge``); off, the line is CAPT's own.
    ``order_stacked_parts`` (``capt`` only): when the model has several prismatic joints (a stack of
    drawers, numbered from the bottom as in the dataset), the target drawer's grasp point is the
    target-index-th handle from the bottom on the stack's front (``stacked_parts``), not the handle
    of the part CAPT labels with the target's index (it often gives a drawer its neighbour's label);
    with fewer handles in view, CAPT's label decides. ``dense_geometry`` (``capt`` only): look for
    handles among all isolated object points rather than the ``num_points`` fed to CAPT (a handle is
    a few of those, kept by one draw and lost by the next). ``slide_along_front`` (``capt`` only): a
    prismatic estimate slides along the normal of its part's flat front (a plane fitted to hundreds
    of points) when that front faces within 0.6 rad of CAPT's direction; off, the direction is
    CAPT's own, only its sign set by the front. ``panel_max_state`` (``capt`` only, rad, 0 off):
    while CAPT's state of a revolute joint is under it (the part is about closed), the hinge edge
    and the handle are looked for on the whole flat panel the moving part lies on (its in-plane
    points joined to it: ``moving_part_geometry.coplanar_panel``), not only on the points CAPT
    labels as moving (it can label the handle's half of a door only).
    """

    source: Source = "oracle"
    checkpoint: str | None = None
    every_k_steps: int = 1
    isolation: IsolationConfig = field(default_factory=IsolationConfig)
    num_points: int = 1024
    noise: NoiseConfig = field(default_factory=NoiseConfig)
    obs_format: ObsFormat = "flat"
    seed: int = 0
    hinge_on_part_edge: bool = True
    order_stacked_parts: bool = True
    dense_geometry: bool = True
    slide_along_front: bool = True
    panel_max_state: float = 0.35

    def validate(self) -> None:
        require(self.every_k_steps >= 1, f"every_k_steps must be >= 1, got {self.every_k_steps}")
        require(self.num_points >= 32, f"num_points must be >= 32, got {self.num_points}")
        require(0.0 <= self.panel_max_state <= 3.15,
                f"panel_max_state must be in [0, pi] rad, got {self.panel_max_state}")
        if self.source == "capt":
            require(self.checkpoint is not None, "source 'capt' needs a checkpoint path")
        self.isolation.validate()
        self.noise.validate()
