"""Refiner ``hinge_on_edge``: a flat part's hinge line lies on its edge away from the handle.

Geometric reason: a closed door, lid or oven door turns about a line in (or just behind) its own
plane along its edge farthest from the handle. A panel with a twin of the grasp's handle
(:func:`~capt_env.wrappers.refiners.handle.twin`) beside it rather than above it is two coplanar
doors meeting between their handles (a double door the network reads as one part; Franka Kitchen's hinged
cabinet): the grasp's door is hinged on the panel's edge on its side of that seam (``pair_doors``).
The direction is projected into the part's plane
(its in-plane component kept, so the network still decides which edge), and the network's line is
kept when it lies within ``tolerance`` of that edge and of the plane, else it is put on the edge
(the ``edge_quantile`` of the ``panel``'s points across the axis). On a real microwave the
network's line was 24-53 cm off; on cabinet doors 14-46 cm.
Must not fire: on a prismatic joint or a part that is not flat; when the direction is more than
60 deg out of the part's plane (not this part's hinge); on a bar (points spreading less than
``min_aspect`` as much across their main direction as along it: an eyeglasses temple), where only
the pivot moves along the line to the grasp point.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import ClassVar

import numpy as np

from capt_common.typed_yaml import require
from capt_env.wrappers.moving_part_geometry import hinge_on_edge
from capt_env.wrappers.refiners.draft import Draft


@dataclass(frozen=True)
class HingeOnEdgeConfig:
    """``tolerance`` (m): the network's line is kept this close to the edge and the plane;
    ``edge_quantile``: the edge is this quantile of the panel's points across the axis (robust to
    strays); ``min_aspect``: a part spreading less than this across its main direction is a bar."""

    tolerance: float = 0.06
    edge_quantile: float = 0.02
    min_aspect: float = 0.25
    pair_doors: bool = True
    """A twin of the grasp's handle beside it (``double_door_seam``) makes the panel a double door: the
    grasp's door is hinged on the panel's edge on its side of the seam between them."""

    def validate(self) -> None:
        require(self.tolerance >= 0, "hinge_on_edge.tolerance must be >= 0 (metres)")
        require(0.0 <= self.edge_quantile < 0.5, "hinge_on_edge.edge_quantile must be in [0, 0.5)")
        require(0.0 <= self.min_aspect <= 1.0, "hinge_on_edge.min_aspect must be in [0, 1]")


class HingeOnEdge:
    """Put a revolute draft's line on its flat part's edge away from the grasp point (settles it)."""

    name: ClassVar[str] = "hinge_on_edge"

    def __init__(self, config: HingeOnEdgeConfig | None = None) -> None:
        self.config = config or HingeOnEdgeConfig()

    def refine(self, draft: Draft) -> bool:
        plane = draft.plane
        if draft.joint_type != "revolute" or plane is None:
            return False
        c = self.config
        grasp = draft.settle_grasp()
        before = (draft.direction, draft.pivot)
        draft.direction, draft.pivot = hinge_on_edge(draft.direction, grasp, plane, draft.moving,
                                                     pivot=draft.pivot, tolerance=c.tolerance,
                                                     edge_quantile=c.edge_quantile,
                                                     min_aspect=c.min_aspect, panel_points=draft.panel,
                                                     other_handles=draft.other_handles,
                                                     pair_doors=c.pair_doors)
        # fired: the line moved (the old pivot over 1 mm off the new line) or turned over 1 mrad; a
        # kept line still gets the projection into the plane, a rounding-sized turn
        off_line = np.cross(before[1] - draft.pivot, draft.direction)
        return bool(np.linalg.norm(off_line) > 1e-3 or float(draft.direction @ before[0]) < np.cos(1e-3))
