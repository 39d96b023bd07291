"""Refiner ``front_normal``: a drawer slides along the normal of its flat front.

Geometric reason: a drawer's front is perpendicular to its slide, and a plane fitted to hundreds of
front points is steadier than the network's per-point votes, a few degrees of which make a pulled
drawer bind or slip out of the fingers (6.3 -> 1.5 deg on 30 unseen resets). The direction becomes
the front's outward normal (away from the body, so it opens).
Must not fire: on a revolute joint, when the part has no flat face, or when that face's normal is
more than ``max_angle`` rad off the network's slide (it is then a drawer's bottom or side, or the
part is not a drawer at all: a sliding door moves in its front's plane).
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import ClassVar

from capt_common.typed_yaml import require
from capt_env.wrappers.estimate import unit
from capt_env.wrappers.moving_part_geometry import faces_along
from capt_env.wrappers.refiners.draft import Draft


@dataclass(frozen=True)
class FrontNormalConfig:
    """``max_angle`` (rad): the front's normal lies within it of the network's slide line."""

    max_angle: float = 0.6

    def validate(self) -> None:
        require(0.0 < self.max_angle <= 1.58, "front_normal.max_angle must be in (0, pi/2] rad")


class FrontNormal:
    """Set a prismatic draft's direction to its front's outward normal."""

    name: ClassVar[str] = "front_normal"

    def __init__(self, config: FrontNormalConfig | None = None) -> None:
        self.config = config or FrontNormalConfig()

    def refine(self, draft: Draft) -> bool:
        plane = draft.plane
        if draft.joint_type != "prismatic" or plane is None:
            return False
        if not faces_along(plane, draft.direction, self.config.max_angle):
            return False
        draft.direction = unit(plane.outward)
        return True
