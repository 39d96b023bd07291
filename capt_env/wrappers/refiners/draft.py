"""The target joint's estimate while the refiners work on it, and what they may look at.

A :class:`Draft` starts as the network's own estimate of the target joint (:func:`network_draft`):
its type, direction, a point on its line, its state and confidence, with no grasp point yet. The
refiners (:mod:`capt_env.wrappers.refiners`) change it in place, in order; :meth:`Draft.estimate`
then settles what none of them set (the grasp point falls back to the moving part's far edge, the
pivot becomes the line's point closest to the grasp point) and returns the
:class:`~capt_env.wrappers.estimate.JointAxisEstimate`. World frame, metres, radians throughout.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import TYPE_CHECKING, Any, ClassVar, Protocol

import numpy as np

from capt_env.wrappers.estimate import JointAxisEstimate, canonical_pivot, grasp_point_of_part, unit
from capt_env.wrappers.moving_part_geometry import PartPlane, faces_along, facing, part_plane, slides_across

if TYPE_CHECKING:
    from perception.inference import ArticulationEstimate, JointEstimate

MIN_HANDLE_POINTS = 3
"""The fewest points of the network's input cloud a handle has: fewer are noise, not a handle."""


@dataclass
class Draft:
    """One look's estimate of the target joint while it is refined (mutable; world frame).

    Evidence (refiners read it): ``points`` (M, 3) the network's input, ``labels`` (M,) its part
    labels, ``moving`` (K, 3) the points it labels as the target joint's moving part (all points
    when it labels fewer than 3), ``network`` its estimate of the target joint (``joint_index``,
    ``type``, ``direction``, ``pivot``, ``state``, ``confidence``), ``model`` the model's config
    (``joint_child_parts``, ``joint_types``), ``target`` the joint's index, ``dense_points`` (D, 3)
    all isolated object points (or None), ``viewpoint`` (3,) the cameras' mean position (or None),
    ``target_hint`` (3,) the target part's centre of mass as the task gives it (or None): it only
    chooses between alike parts (a double door's leaves, a stack's drawers), never sets the estimate.

    Working geometry (refiners may replace it): ``handle_cloud`` the points handles are looked for
    among and ``handle_min_points`` the fewest points of a handle there; ``panel`` the flat panel the
    moving part lies on (its edges hold a hinge; starts as ``moving``); :attr:`plane` the moving
    part's plane.

    The estimate: ``joint_type``, ``direction`` (3,) unit, ``pivot`` (3,) a point on the line,
    ``state`` (rad or m), ``confidence``, ``grasp`` (3,) or None until a handle is found or the
    grasp is settled (:meth:`settle_grasp`), ``from_handle`` (the grasp point is on a handle),
    ``other_handles`` the other handles found on the panel that could be the grasp's twin on a double
    door's other leaf (each (3,)). ``fired`` lists the refiners that changed the draft, in order.
    """

    points: np.ndarray
    labels: np.ndarray
    moving: np.ndarray
    network: JointEstimate
    model: Any
    target: int
    dense_points: np.ndarray | None
    handle_cloud: np.ndarray
    handle_min_points: int
    panel: np.ndarray
    joint_type: str
    direction: np.ndarray
    pivot: np.ndarray
    state: float
    confidence: float
    grasp: np.ndarray | None = None
    from_handle: bool = False
    viewpoint: np.ndarray | None = None
    target_hint: np.ndarray | None = None
    other_handles: list[np.ndarray] = field(default_factory=list)
    fired: list[str] = field(default_factory=list)
    _plane: PartPlane | None = field(default=None, repr=False)
    _plane_known: bool = field(default=False, repr=False)
    _sliding: PartPlane | None = field(default=None, repr=False)
    _sliding_known: bool = field(default=False, repr=False)
    _settled: bool = field(default=False, repr=False)

    @property
    def plane(self) -> PartPlane | None:
        """The moving part's plane (fitted on first use, :func:`moving_part_plane`), or the plane a
        refiner chose (:meth:`use_plane`); None when the part is not flat."""
        if not self._plane_known:
            self.use_plane(moving_part_plane(self.points, self.moving, self.network.type,
                                             unit(self.network.direction), self.viewpoint))
        return self._plane

    @property
    def face(self) -> PartPlane | None:
        """The face a handle stands off: :attr:`plane`, or for a part that slides across its upright
        face (a window sash, a sliding door; :func:`slides_across`) that face; None otherwise."""
        if self.plane is not None or self.joint_type != "prismatic":
            return self.plane
        plane = self.sliding_face()
        return plane if slides_across(plane, self.direction) else None

    def sliding_face(self) -> PartPlane | None:
        """The moving part's plane with its outward normal turned towards ``viewpoint`` (a sash in
        front of its pane is seen from its outer side; the away-from-the-body rule of
        :func:`part_plane` turns it round when a handle and a plinth standing out in front outweigh
        a thin frame behind), or as :func:`part_plane` orients it without a viewpoint."""
        if not self._sliding_known:  # fitted once per draft: the refiners and the handle ask again
            plane = part_plane(self.points, self.moving)
            if plane is not None and self.viewpoint is not None:
                plane = facing(plane, self.viewpoint)
            self._sliding, self._sliding_known = plane, True
        return self._sliding

    def use_plane(self, plane: PartPlane | None) -> None:
        """Take ``plane`` as the moving part's plane (a stack's front for stacked drawers)."""
        self._plane, self._plane_known = plane, True

    @property
    def settled(self) -> bool:
        """Whether the grasp point (and with it the pivot) is final (:meth:`settle_grasp`)."""
        return self._settled

    def settle_grasp(self) -> np.ndarray:
        """Fix the grasp point (3,): the handle a refiner found, else the moving part's far edge from
        the current axis (:func:`~capt_env.wrappers.estimate.grasp_point_of_part`); the pivot becomes
        the line's point closest to it. Idempotent. A refiner that turns the direction after this
        moves the pivot itself (a sign flip needs nothing: the closest point stays)."""
        if not self._settled:
            if self.grasp is None:
                self.grasp = grasp_point_of_part(self.moving, self.joint_type, self.direction,
                                                 np.asarray(self.network.pivot))
            self.pivot = canonical_pivot(self.direction, self.pivot, self.grasp)
            self._settled = True
        assert self.grasp is not None
        return self.grasp

    def estimate(self) -> JointAxisEstimate:
        """The settled estimate (see :meth:`settle_grasp`)."""
        grasp = self.settle_grasp()
        return JointAxisEstimate(self.joint_type, self.direction, self.pivot, float(self.state), grasp,
                                 float(self.confidence))


class Refiner(Protocol):
    """One geometric correction of a :class:`Draft`. ``name`` is the name configs use."""

    name: ClassVar[str]

    def refine(self, draft: Draft) -> bool:
        """Change ``draft`` in place where the refiner's rule holds; True when it changed it."""
        ...


def moving_part_plane(points: np.ndarray, moving: np.ndarray, joint_type: str,
                      direction: np.ndarray, viewpoint: np.ndarray | None = None) -> PartPlane | None:
    """The plane of the ``moving`` part's points (M, 3) (:func:`part_plane`, normal away from the
    ``points`` (N, 3), or towards ``viewpoint`` (3,) for a part with no body behind it); for a
    prismatic part only when it faces along the slide ``direction`` (3,): an open drawer's largest
    plane is its bottom or a side, not its front. None otherwise."""
    plane = part_plane(points, moving, viewpoint)
    if joint_type == "prismatic" and not faces_along(plane, direction):
        return None
    return plane


def network_draft(result: ArticulationEstimate, points: np.ndarray, target: int, model: Any,
                  dense_points: np.ndarray | None = None, viewpoint: np.ndarray | None = None,
                  target_hint: np.ndarray | None = None) -> Draft:
    """The draft of the network's estimate ``result`` of the cloud ``points`` (M, 3) for joint
    ``target`` (clipped to the joints the model has): its own type, direction, pivot, state and
    confidence; the moving part is the points labelled with the joint's child part (all points when
    fewer than 3 are, or the model names no child parts). ``model``: the model's config. A
    cross-category model reports only the slots it finds present: when the target slot is not among
    them, the most confident joint it found stands in. ``target_hint`` (3,): the target part's centre
    of mass, when the task gives it."""
    points = np.asarray(points, dtype=np.float64)
    by_slot = {j.joint_index: j for j in result.joints}
    k = min(int(target), max(by_slot))
    joint = by_slot.get(k) or max(result.joints, key=lambda j: j.confidence)
    k = joint.joint_index
    labels = np.asarray(result.part_labels)
    moving = points
    child_parts = getattr(model, "joint_child_parts", None)
    if child_parts is not None and k < len(child_parts):
        mask = labels == int(child_parts[k])
        if mask.sum() >= 3:
            moving = points[mask]
    dense = None if dense_points is None else np.asarray(dense_points, dtype=np.float64)
    return Draft(points=points, labels=labels, moving=moving, network=joint, model=model, target=k,
                 dense_points=dense, handle_cloud=points, handle_min_points=MIN_HANDLE_POINTS,
                 panel=moving, joint_type=joint.type, direction=unit(joint.direction),
                 pivot=np.asarray(joint.pivot, dtype=np.float64), state=float(joint.state),
                 confidence=float(joint.confidence), viewpoint=viewpoint, target_hint=target_hint)
