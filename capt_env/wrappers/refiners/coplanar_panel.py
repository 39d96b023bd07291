"""Refiner ``coplanar_panel``: a closed part's edges and handle are looked for on its whole flat panel.

Geometric reason: a closed door or lid lies in one plane, and all of it touches the part the network
labelled. The network can label only the handle's half of a closed door as moving (cabinet door seed
150: 16 of its 40 cm), whose edge is mid-door; the door's other in-plane points joined to that half
(through neighbours at most ``link_radius`` apart, within ``band`` of the plane) give its full
extent, whose edge away from the handle is the hinge. The panel replaces the labelled points where
``handle`` and ``hinge_on_edge`` look for the handle and the edges.
Must not fire: on a prismatic joint, a part that is not flat, or once the network's state says the
part is open (``max_state`` rad or more): an open door is coplanar with whatever it happens to align
with (at 90 deg a cabinet's side wall, joined at the hinge).
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import ClassVar

from capt_common.typed_yaml import require
from capt_env.wrappers.moving_part_geometry import coplanar_panel
from capt_env.wrappers.refiners.draft import Draft


@dataclass(frozen=True)
class CoplanarPanelConfig:
    """``max_state`` (rad): grow the panel only while the network's state is under it; ``band`` (m):
    in-plane points lie this close to the plane; ``link_radius`` (m): in-plane neighbours this close
    join the panel."""

    max_state: float = 0.35
    band: float = 0.01
    link_radius: float = 0.03

    def validate(self) -> None:
        require(0.0 <= self.max_state <= 3.15, f"coplanar_panel.max_state must be in [0, pi] rad, "
                                               f"got {self.max_state}")
        require(self.band > 0 and self.link_radius > 0,
                "coplanar_panel.band and coplanar_panel.link_radius must be > 0 (metres)")


class CoplanarPanel:
    """Set the draft's ``panel`` to the flat panel its closed moving part lies on."""

    name: ClassVar[str] = "coplanar_panel"

    def __init__(self, config: CoplanarPanelConfig | None = None) -> None:
        self.config = config or CoplanarPanelConfig()

    def refine(self, draft: Draft) -> bool:
        if draft.joint_type != "revolute" or draft.plane is None:
            return False
        if not abs(float(draft.state)) < self.config.max_state:
            return False
        draft.panel = coplanar_panel(draft.points, draft.moving, draft.plane, band=self.config.band,
                                     link_radius=self.config.link_radius)
        return len(draft.panel) > len(draft.moving)
