"""Varied training clouds (``GenerateConfig.variation``, YAML key ``variation:``): object geometry,
distractors on the table, robot-centric viewpoints and depth-sensor noise. Everything is off by
default, and a config with everything off renders byte for byte the datasets made before these
options existed.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field
from typing import Literal

from capt_common.typed_yaml import ConfigError, require
from capt_env.objects.style import GeometryVariation

TASK_CAMERA_EYES: tuple[tuple[float, float, float], ...] = ((-0.45, -0.35, 0.45), (-0.45, 0.35, 0.45))
"""The opening task's camera eyes relative to the object's centre (world axes, metres): the default
``CameraConfig.eye`` (the right camera) and the left one of ``configs/tasks/two_cameras.yaml``."""


def _pair(name: str, value: tuple[float, float], low: float, high: float = math.inf) -> None:
    lo, hi = value
    require(math.isfinite(lo) and low <= lo <= hi <= high,
            f"{name} must be [low, high] with {low} <= low <= high <= {high}, got {list(value)}")


@dataclass(frozen=True)
class Distractors:
    """Random primitives (boxes, upright cylinders, spheres) on the table around the object, labelled
    background (part label -1) and kept in the cloud; never overlapping the object.

    Per view, ``count`` = [low, high] of them (uniform, inclusive), each ``size`` = [low, high]
    metres across its largest side, standing on the table at a gap uniform in ``gap`` = [low, high]
    metres from the object's footprint (the table-plane bounding box of every object link at the
    view's joint states) and at least 1 cm from each other. One that finds no place is left out.
    """

    count: tuple[int, int] = (0, 0)
    size: tuple[float, float] = (0.04, 0.14)
    gap: tuple[float, float] = (0.01, 0.15)

    @property
    def enabled(self) -> bool:
        return self.count[1] > 0

    def validate(self) -> None:
        lo, hi = self.count
        require(0 <= lo <= hi <= 8,
                f"count must be [low, high] with 0 <= low <= high <= 8, got {list(self.count)}")
        _pair("size", self.size, 0.01, 0.4)
        _pair("gap", self.gap, 0.0, 1.0)


@dataclass(frozen=True)
class Viewpoints:
    """Where the camera stands. ``ring``: the ``camera`` config's sphere about the object (distance,
    azimuth from the object's front, elevation). ``robot``: where the opening task's cameras stand,
    one of ``eyes`` (metres, world axes, relative to the object's bounding-box centre; default the
    task's right and left cameras) per view plus a uniform offset of up to ``jitter`` metres on each
    axis, the object placed where the task places it (its category's ``object_xy``, e.g. a laptop
    under the robot's resting hand) with the task's position and yaw noise.
    """

    mode: Literal["ring", "robot"] = "ring"
    eyes: tuple[tuple[float, float, float], ...] = TASK_CAMERA_EYES
    jitter: float = 0.05

    def validate(self) -> None:
        require(len(self.eyes) >= 1, "eyes must hold at least one [x, y, z] (metres)")
        for eye in self.eyes:
            require(0.15 <= math.hypot(*eye) <= 3.0, f"eyes: {list(eye)} must lie 0.15-3 m from the object")
        require(0.0 <= self.jitter <= 0.3, f"jitter must be in [0, 0.3] metres, got {self.jitter}")


@dataclass(frozen=True)
class SensorNoise:
    """Depth-sensor noise, applied to the rendered cloud in this order:

    - ``edge_dropout``: probability (0-1) of dropping a pixel at a depth edge, i.e. whose range from
      the camera differs from one of its 4 image neighbours' by more than ``edge_threshold_m``
      metres (the flying and missing pixels of real depth cameras at silhouettes);
    - ``jitter_m`` (metres, Gaussian standard deviation) and ``outlier_fraction`` (stray points
      added, as a fraction of the kept points, uniform in their bounding box): exactly
      ``perception.corruption.Corruption``, the ``sensor_noise`` of ``capt train``; a stray point
      takes the label of its nearest kept point, as in training.
    """

    jitter_m: float = 0.0
    outlier_fraction: float = 0.0
    edge_dropout: float = 0.0
    edge_threshold_m: float = 0.02

    @property
    def enabled(self) -> bool:
        return self.jitter_m > 0 or self.outlier_fraction > 0 or self.edge_dropout > 0

    def validate(self) -> None:
        require(math.isfinite(self.jitter_m) and 0.0 <= self.jitter_m <= 0.05,
                f"jitter_m must be in [0, 0.05] metres, got {self.jitter_m}")
        require(0.0 <= self.outlier_fraction <= 1.0,
                f"outlier_fraction must be in [0, 1], got {self.outlier_fraction}")
        require(0.0 <= self.edge_dropout <= 1.0, f"edge_dropout must be in [0, 1], got {self.edge_dropout}")
        require(self.edge_threshold_m > 0,
                f"edge_threshold_m must be > 0 metres, got {self.edge_threshold_m}")


@dataclass(frozen=True)
class Variation:
    """What varies beyond the instance, the joint states and the ring of viewpoints; each part is
    documented on its class: ``geometry`` (:class:`capt_env.objects.style.GeometryVariation`: panel
    shapes, handles, interiors, drawer openings, drawer and door proportions; procedural categories
    only, a user ``object`` file is rendered as it is), ``distractors``, ``viewpoints``,
    ``sensor_noise``."""

    geometry: GeometryVariation = field(default_factory=GeometryVariation)
    distractors: Distractors = field(default_factory=Distractors)
    viewpoints: Viewpoints = field(default_factory=Viewpoints)
    sensor_noise: SensorNoise = field(default_factory=SensorNoise)

    @property
    def enabled(self) -> bool:
        """True when anything varies (else the generator renders exactly as without this option)."""
        return self != Variation()

    @property
    def needs_scene(self) -> bool:
        """True when the rendered scene differs from the opening task's (see ``dataset.scene_env``)."""
        return self.geometry.enabled or self.distractors.enabled or self.viewpoints.mode == "robot"

    def validate(self) -> None:
        for name in ("distractors", "viewpoints", "sensor_noise"):
            try:
                getattr(self, name).validate()
            except ConfigError as err:
                raise ConfigError(f"variation.{name}: {err}") from None
