"""Refiner ``opening_sign``: the axis is signed so that opening moves the part out of its body.

Geometric reason: a closed part lies on the outside of its body, so increasing the state must move
its grasp point along the face's outward normal: for a hinge the grasp point's velocity
``direction x (grasp - pivot)``, for a slide the direction itself. The sign of a hinge's axis is a
global property of the shape (which side the hinge is on), the one thing a single view most often
gets wrong while the line is right. A hinge's sign needs the grasp point, so this settles it.
Must not fire: when the part has no flat face (a prismatic part's face must face along its slide),
or the sign already opens the part.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import ClassVar

from capt_env.wrappers.moving_part_geometry import opening_direction
from capt_env.wrappers.refiners.draft import Draft


@dataclass(frozen=True)
class OpeningSignConfig:
    """No settings: the sign rule has no threshold."""

    def validate(self) -> None:
        pass


class OpeningSign:
    """Flip the draft's direction when the other sign opens its part."""

    name: ClassVar[str] = "opening_sign"

    def __init__(self, config: OpeningSignConfig | None = None) -> None:
        self.config = config or OpeningSignConfig()

    def refine(self, draft: Draft) -> bool:
        plane = draft.plane
        if plane is None:
            return False
        before = draft.direction
        if draft.joint_type == "prismatic":
            draft.direction = opening_direction("prismatic", before, draft.pivot, draft.pivot, plane.outward)
        else:
            grasp = draft.settle_grasp()
            draft.direction = opening_direction("revolute", before, draft.pivot, grasp, plane.outward)
        return float(draft.direction @ before) < 0.0
