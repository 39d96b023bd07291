"""Refiner ``edge_direction``: a hinge runs along an edge of its rectangular part.

Geometric reason: a door's or lid's hinge lies along one of the part's edges, so its direction is
an edge's direction in the part's plane. A single view's estimate of a lid's hinge often errs within
the lid's plane by 5-25 deg, which moves the lid's far edge, where the grasp point is looked for, to
a corner. The part's in-plane points are fitted with their minimum-area rectangle, and the direction
is turned onto the rectangle's edge nearest to it (its sign kept). It runs on the part's own points,
not the coplanar panel: a panel's rectangle includes the frame around an open door, and turned the
line 5-11 deg off during pulls.
Must not fire: on a prismatic joint; on a part that is not a rectangle (its convex hull fills less
than ``min_fill`` of the rectangle: a round washing-machine door) or is a bar (an eyeglasses temple);
when the nearest edge is more than ``max_turn`` rad away or the direction is more than 60 deg out of
the part's plane (not a hinge of this part). Every direction in the plane lies within 45 deg of one
of a rectangle's edges, so at the default ``max_turn`` (pi/4) it is always turned onto the nearer
one: at 0.6 rad a hinge read 34-45 deg off its edge was left tilted (a cabinet door at reset, 42 deg
after ``hinge_on_edge`` had put its line on the edge).
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import ClassVar

import numpy as np

from capt_common.typed_yaml import require
from capt_env.wrappers.moving_part_geometry import edge_aligned_direction
from capt_env.wrappers.refiners.draft import Draft


@dataclass(frozen=True)
class EdgeDirectionConfig:
    """``max_turn`` (rad): the farthest the direction is turned; ``min_fill``: the share of its
    rectangle a part's hull fills to count as a rectangle; ``band`` (m): the part's points this close
    to its plane are fitted; ``min_aspect``: a part spreading less than this across its main
    direction as along it is a bar."""

    max_turn: float = math.pi / 4
    min_fill: float = 0.85
    band: float = 0.01
    min_aspect: float = 0.25

    def validate(self) -> None:
        require(0.0 <= self.max_turn <= 1.58, "edge_direction.max_turn must be in [0, pi/2] rad")
        require(0.0 < self.min_fill <= 1.0, "edge_direction.min_fill must be in (0, 1]")
        require(self.band > 0, "edge_direction.band must be > 0 (metres)")
        require(0.0 <= self.min_aspect <= 1.0, "edge_direction.min_aspect must be in [0, 1]")


class EdgeDirection:
    """Turn a revolute draft's direction onto the nearer edge of its flat rectangular part."""

    name: ClassVar[str] = "edge_direction"

    def __init__(self, config: EdgeDirectionConfig | None = None) -> None:
        self.config = config or EdgeDirectionConfig()

    def refine(self, draft: Draft) -> bool:
        if draft.joint_type != "revolute" or draft.plane is None:
            return False
        c = self.config
        before = draft.direction
        draft.direction = edge_aligned_direction(before, draft.plane, draft.moving, max_turn=c.max_turn,
                                                 min_fill=c.min_fill, band=c.band, min_aspect=c.min_aspect)
        return float(np.linalg.norm(draft.direction - before)) > 1e-9
