"""Refiner ``stacked_parts``: the k-th drawer of a stack is the k-th handle from the bottom.

Geometric reason: a drawer cabinet's joints are numbered from the bottom drawer up, and its drawers
share one flat front with one handle each, stacked along world up. The network segments drawers
from the body well but often gives a drawer its neighbour's label, so its own label can name the
wrong handle; counting the handles on the front from the bottom cannot. The front's plane is the
drawers' union as segmented, or the target drawer's alone when that union is not flat (the network
gave a drawer some of the carcass's top or side), and it must face along the slide. A handle in a
stack needs only ``handle_share`` of the points a lone handle does: a low or partly hidden bar shows
few points, and counting from the bottom, a missed low handle names the next one up.
When the task names its target part (``Draft.target_hint``, the part's centre of mass) the handle
nearest that height is the target's instead: a user file numbers its drawers in any order.
Must not fire: a revolute joint, a model with fewer than two prismatic joints, a front that is not
flat or does not face along the slide, or fewer than k + 1 handles in view (none, with the target
part named; the label decides).
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any, ClassVar

import numpy as np

from capt_common.typed_yaml import require
from capt_env.wrappers.moving_part_geometry import PartPlane, faces_along, part_plane
from capt_env.wrappers.refiners.draft import MIN_HANDLE_POINTS, Draft
from capt_env.wrappers.stacked_parts import kth_handle_from_bottom


@dataclass(frozen=True)
class StackedPartsConfig:
    """``face_max_angle`` (rad): the stack's front faces within it of the slide's line;
    ``handle_share``: a handle in a stack needs this share of the points a lone handle does."""

    face_max_angle: float = 0.6
    handle_share: float = 0.25

    def validate(self) -> None:
        require(0.0 < self.face_max_angle <= 1.58, "stacked_parts.face_max_angle must be in (0, pi/2] rad")
        require(0.0 < self.handle_share <= 1.0, "stacked_parts.handle_share must be in (0, 1]")


def stacked_handle(points: np.ndarray, handle_cloud: np.ndarray, min_points: int, labels: np.ndarray,
                   model: Any, k: int, direction: np.ndarray, config: StackedPartsConfig,
                   target_hint: np.ndarray | None = None) -> tuple[PartPlane | None, np.ndarray | None]:
    """(front plane, centre (3,) of the k-th handle from the bottom among ``handle_cloud``) of a
    stack of prismatic parts in ``points`` (M, 3) with part ``labels`` (M,), or (None, None) when
    ``model`` has fewer than two prismatic joints, neither the stacked parts together nor the target
    alone are flat and face along the slide ``direction`` (3,), or fewer than k + 1 handles are in
    view; with ``target_hint`` (3,), the task's target part's centre, the handle nearest its height.
    World frame, metres."""
    stacked = [int(c) for c, t in zip(model.joint_child_parts, model.joint_types, strict=False)
               if t == "prismatic"]
    if len(stacked) < 2:
        return None, None
    front = points[np.isin(labels, stacked)]
    plane = part_plane(points, front)
    if not faces_along(plane, direction, config.face_max_angle):
        front = points[labels == int(model.joint_child_parts[k])]
        plane = part_plane(points, front)
        if not faces_along(plane, direction, config.face_max_angle):
            return None, None
    fewest = max(MIN_HANDLE_POINTS, int(min_points * config.handle_share))
    height = None if target_hint is None else float(target_hint[2])
    handle = kth_handle_from_bottom(handle_cloud, front, k, plane=plane, min_points=fewest,
                                    target_height=height)
    return (plane, handle) if handle is not None else (None, None)


class StackedParts:
    """Grasp the target-index-th handle from the bottom of a drawer stack; the plane is its front."""

    name: ClassVar[str] = "stacked_parts"

    def __init__(self, config: StackedPartsConfig | None = None) -> None:
        self.config = config or StackedPartsConfig()

    def refine(self, draft: Draft) -> bool:
        if (draft.joint_type != "prismatic" or draft.grasp is not None
                or getattr(draft.model, "joint_child_parts", None) is None):
            return False
        plane, handle = stacked_handle(draft.points, draft.handle_cloud, draft.handle_min_points,
                                       draft.labels, draft.model, draft.target, draft.direction,
                                       self.config, draft.target_hint)
        if handle is None:
            return False
        draft.use_plane(plane)
        draft.grasp, draft.from_handle = handle, True
        return True
