"""Typed configuration of the opening tasks (object choice, placement, cameras, success), YAML-loadable."""

from __future__ import annotations

from dataclasses import dataclass, field
from pathlib import Path
from typing import Any, Literal

from capt_common.typed_yaml import ConfigError, require

Split = Literal["train", "val", "test", "all"]
ClosedLimit = Literal["auto", "lower", "upper"]
MjcfAngle = Literal["auto", "radian", "degree"]
NAMED_FRONTS: dict[str, float] = {"+x": 0.0, "x": 0.0, "+y": 1.5707963267948966, "y": 1.5707963267948966,
                                  "-x": 3.141592653589793, "-y": -1.5707963267948966}
"""Named front directions of a user file: the azimuth (radians, file frame) of its front's outward
normal."""

DEFAULT_OBJECT_XY: tuple[float, float] = (0.3, 0.0)
"""World (x, y) metres of an object's bounding-box centre when neither the task nor its category
says otherwise."""
CATEGORY_OBJECT_XY: dict[str, tuple[float, float]] = {"laptop": (-0.08, 0.0)}
"""Per-category placement (see :class:`TaskConfig`)."""
USER_GRASP_X: tuple[float, float] = (0.02, 0.24)
USER_GRASP_MAX_Y: float = 0.2
"""World metres. A user file placed by default (no ``object_xy``) is moved, before the episode's
noise, by the least distance that brings its closed grasp target into x in ``USER_GRASP_X`` and
|y| <= ``USER_GRASP_MAX_Y``: the span of the procedural instances' grasp targets at their placements
(x 0.02-0.24, |y| <= 0.2), where the opener was developed. A large file centred at 0.3 m can leave
its handle under the resting hand (Franka Kitchen's hinged cabinet, 60 cm deep: x -0.08) or 40 cm
to the side (its sliding cabinet), where the Panda's wrist cannot turn with the
part."""


RESTING_ARM_FRONT_X: float = 0.06
RESTING_ARM_BOTTOM_Z: float = 0.13
RESTING_ARM_HALF_Y: float = 0.15
"""World metres. The space the Panda's resting arm (ManiSkill's rest pose with its reset noise) takes
in front of its base: over 60 resets the collision meshes of links 5-7, the hand and the fingers
reached x <= 0.059, z >= 0.132 and |y| <= 0.132 (|y| rounded up to 0.15: the noise is Gaussian)."""
RESTING_ARM_CLEARANCE: float = 0.02
"""World metres. Every episode the object is moved along +x, if need be, so that the part of its
closed bounding box at the resting arm's heights and sides starts at least this far in front of
``RESTING_ARM_FRONT_X``: otherwise the arm starts against the object (the default placement left
links 6-7 or the hand touching a deep oven's door on a quarter of the resets, a washing machine's
on a sixth, and Franka Kitchen's cabinet handles against the hand), holding a door that then falls
open as it moves, or dragging the handle it rests on."""


@dataclass(frozen=True)
class CameraConfig:
    """One depth camera looking at the object.

    The camera always looks at the object's bounding-box centre. By default its eye is ``eye``
    (metres, world axes, relative to that centre) plus a uniform offset of up to ``jitter`` metres on
    each axis per episode. With ``random_view`` the eye is instead drawn per episode on a sphere about
    the centre: ``distance`` metres, ``azimuth`` radians measured from the object's front direction
    (0 = straight in front, positive = counter-clockwise seen from above) and ``elevation`` radians
    above the horizontal. ``fov`` is the vertical field of view in radians.
    """

    name: str = "depth_camera"
    eye: tuple[float, float, float] = (-0.45, -0.35, 0.45)
    width: int = 128
    height: int = 128
    fov: float = 1.0
    near: float = 0.05
    far: float = 4.0
    jitter: float = 0.0
    random_view: bool = False
    distance: tuple[float, float] = (0.6, 0.9)
    azimuth: tuple[float, float] = (-1.1, 1.1)
    elevation: tuple[float, float] = (0.3, 0.9)

    def validate(self) -> None:
        require(self.width >= 8 and self.height >= 8, f"camera {self.name}: width/height must be >= 8")
        require(0.05 < self.fov < 3.0, f"camera {self.name}: fov must be in (0.05, 3.0) radians")
        require(0 < self.near < self.far, f"camera {self.name}: need 0 < near < far")
        require(self.jitter >= 0, f"camera {self.name}: jitter must be >= 0")
        for key in ("distance", "azimuth", "elevation"):
            lo, hi = getattr(self, key)
            require(lo <= hi, f"camera {self.name}: {key} must be (low, high) with low <= high")
        require(self.distance[0] > self.near, f"camera {self.name}: distance must exceed near")
        require(-1.5 < self.elevation[0] and self.elevation[1] < 1.5,
                f"camera {self.name}: elevation must lie in (-1.5, 1.5) radians")


@dataclass(frozen=True)
class TaskConfig:
    """What the opening task builds and how it randomises each episode.

    Object: a procedural ``category`` (with instances drawn from ``split`` or from ``instance_ids``)
    or a URDF/MJCF file ``object`` (then ``joint`` names the joint to open; default the first
    movable one, and ``scale`` scales it). Exactly one of ``category``/``object`` is set.

    Placement (world frame, metres/radians): the object's bounding-box centre is put at
    ``object_xy`` +- ``object_xy_noise`` on the table top, its front facing the robot, turned by a
    yaw uniform in +-``yaw_noise``. The Panda's base is at (-0.615, 0) and its resting hand near
    x = 0. ``object_xy`` None (the default) means the category's placement
    (:data:`CATEGORY_OBJECT_XY`, else :data:`DEFAULT_OBJECT_XY`): 0.3 m keeps most deep objects
    (ovens, cabinets) clear of the hand at reset; a laptop sits under the resting hand at -0.08 m, because
    its lid's lip, swung up to vertical 0.2-0.3 m behind where it started, is beyond the Panda's
    reach from 0.3 m. A user file placed by default is then moved so that its closed grasp target
    lies where the procedural ones do (:data:`USER_GRASP_X`, :data:`USER_GRASP_MAX_Y`). Every
    episode, after the noise and yaw, an object whose closed bounding box would reach the resting arm
    is moved straight away from the robot until it clears it (:data:`RESTING_ARM_CLEARANCE`): the
    arm never starts against the object.

    Joint states at reset: the target joint starts at a fraction of its range uniform in
    ``target_init_fraction``; other joints uniform in ``other_init_fraction`` of their ranges.
    Both default to nearly closed (as in ManiSkill's OpenCabinet tasks): an open drawer above the
    target one reaches into the Panda's wrist at reset. Data generation opens everything at random.

    User files (all lengths after ``scale``, frames are the file's root frame):

    - ``front_yaw``: azimuth (radians, counter-clockwise about +z from the file's +x) of the
      object's front normal, or one of ``"+x"``, ``"-x"``, ``"+y"``, ``"-y"``; None guesses it from
      the moving part (see ``docs/user_objects.md``). The task turns this direction to the robot.
    - ``closed``: which limit of each joint is closed (``lower``/``upper``); ``auto`` takes, per
      joint, the limit at which the whole object's bounding box is smaller (a part swung or pulled
      out takes room), the lower one on a tie. Joint states are then 0 closed and grow while opening.
    - ``joint_damping`` (N m s/rad or N s/m) and ``joint_friction`` (Coulomb, N m or N) replace the
      file's values on every movable joint; ``part_mass`` (kg) sets the moving link's mass (inertia
      scaled with it; a part lighter than ``object_loading.MIN_PART_MASS``, 50 g, is raised to it);
      ``density`` (kg/m^3) is used for links whose file gives no mass.
    - ``grasp_point`` (metres, file frame at the closed state) or ``handle`` (the name of a link or
      geom on the moving part) sets the grasp target; default: a handle found by name, else by
      geometry (the part of the moving link standing off its outer face).
    - ``visual_groups``: MJCF geom groups drawn by the cameras; ``mjcf_angle``: the unit of an MJCF
      file's angles (``auto``: its compiler, or radians for an included fragment with radian ranges).

    Success: the target joint is opened past ``success_fraction`` of its range and at rest
    (child link speed below ``rest_linear_speed`` m/s and ``rest_angular_speed`` rad/s).
    """

    category: str | None = None
    object: str | None = None
    joint: str | None = None
    scale: float = 1.0
    front_yaw: float | str | None = None
    closed: ClosedLimit = "auto"
    joint_damping: float | None = None
    joint_friction: float | None = None
    part_mass: float | None = None
    density: float | None = None
    grasp_point: tuple[float, float, float] | None = None
    handle: str | None = None
    visual_groups: tuple[int, ...] = (0, 1, 2)
    mjcf_angle: MjcfAngle = "auto"
    split: Split = "train"
    instance_ids: tuple[int, ...] | None = None
    object_xy: tuple[float, float] | None = None
    object_xy_noise: tuple[float, float] = (0.05, 0.05)
    yaw_noise: float = 0.2
    target_init_fraction: tuple[float, float] = (0.0, 0.05)
    other_init_fraction: tuple[float, float] = (0.0, 0.05)
    success_fraction: float = 0.75
    rest_linear_speed: float = 0.1
    rest_angular_speed: float = 1.0
    cameras: tuple[CameraConfig, ...] = field(default_factory=lambda: (CameraConfig(),))

    def validate(self) -> None:
        require(
            (self.category is None) != (self.object is None),
            "exactly one of 'category' and 'object' must be set",
        )
        if self.category is not None:
            from capt_env.objects.registry import CATEGORIES

            require(
                self.category in CATEGORIES,
                f"unknown category {self.category!r}; known: {list(CATEGORIES)}",
            )
        if self.object is None:
            for key in USER_FILE_KEYS:
                if getattr(self, key) != getattr(_DEFAULTS, key):
                    raise ConfigError(f"{key!r} applies to a user 'object' file; it needs 'object'")
        if isinstance(self.front_yaw, str):
            require(self.front_yaw in NAMED_FRONTS,
                    f"front_yaw must be radians or one of {list(NAMED_FRONTS)}, got {self.front_yaw!r}")
        for key in ("joint_damping", "joint_friction"):
            value = getattr(self, key)
            require(value is None or value >= 0, f"{key} must be >= 0, got {value}")
        for key in ("part_mass", "density"):
            value = getattr(self, key)
            require(value is None or value > 0, f"{key} must be > 0, got {value}")
        require(self.grasp_point is None or self.handle is None,
                "set at most one of 'grasp_point' and 'handle'")
        require(self.scale > 0, f"scale must be > 0, got {self.scale}")
        for name in ("target_init_fraction", "other_init_fraction"):
            lo, hi = getattr(self, name)
            require(0.0 <= lo <= hi <= 1.0, f"{name} must satisfy 0 <= low <= high <= 1, got {(lo, hi)}")
        require(0.0 < self.success_fraction <= 1.0,
                f"success_fraction must be in (0, 1], got {self.success_fraction}")
        require(self.yaw_noise >= 0, f"yaw_noise must be >= 0, got {self.yaw_noise}")
        require(all(n >= 0 for n in self.object_xy_noise),
                f"object_xy_noise must be >= 0, got {self.object_xy_noise}")
        require(self.object_xy is None or len(self.object_xy) == 2,
                f"object_xy must be [x, y] metres or null, got {self.object_xy}")
        require(len(self.cameras) >= 1, "at least one camera is needed")
        names = [c.name for c in self.cameras]
        require(len(set(names)) == len(names), f"camera names must be unique, got {names}")
        for cam in self.cameras:
            cam.validate()
        if self.instance_ids is not None:
            require(len(self.instance_ids) > 0, "instance_ids must not be empty")
            require(all(i >= 0 for i in self.instance_ids), "instance_ids must be >= 0")

    def front_yaw_radians(self) -> float | None:
        """``front_yaw`` as radians (named axes converted), or None when it is to be guessed."""
        if isinstance(self.front_yaw, str):
            return NAMED_FRONTS[self.front_yaw]
        return None if self.front_yaw is None else float(self.front_yaw)

    def placement_xy(self) -> tuple[float, float]:
        """World (x, y) metres of the object's bounding-box centre before noise: ``object_xy``, or
        the category's default placement when it is None."""
        if self.object_xy is not None:
            return (float(self.object_xy[0]), float(self.object_xy[1]))
        return CATEGORY_OBJECT_XY.get(self.category or "", DEFAULT_OBJECT_XY)


USER_FILE_KEYS = ("joint", "front_yaw", "closed", "joint_damping", "joint_friction", "part_mass", "density",
                  "grasp_point", "handle", "visual_groups", "mjcf_angle")
"""Task keys that describe a user object file and need ``object``."""
_DEFAULTS = TaskConfig(category="laptop")


def read_task_yaml(path: str | Path) -> dict[str, Any]:
    """The TaskConfig keys of a YAML file, as a mapping (validated where it is used).

    :raises FileNotFoundError: if the file does not exist.
    :raises ValueError: if it does not hold a mapping.
    """
    import yaml

    path = Path(path)
    if not path.is_file():
        raise FileNotFoundError(f"task file not found: {path}")
    raw = yaml.safe_load(path.read_text()) or {}
    if not isinstance(raw, dict):
        raise ValueError(f"{path}: expected a mapping of TaskConfig keys, got {type(raw).__name__}")
    return raw
