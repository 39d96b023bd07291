"""Simulator-independent description of an articulated object: links made of boxes (and, for varied
geometry, cylinders and convex meshes), 1-DoF joints.

Frames: every link has its own frame; a shape's ``pos``/``quat`` (or a mesh's vertices) are in its
link's frame. A joint's
``origin``/``axis`` are given in the PARENT link's frame at joint state 0, and at state 0 the child
frame coincides with the parent frame (so child geometry is written in the same coordinates as the
parent's at the closed/zero pose). The object frame is the base link's frame: +z up, the object rests
on the plane z = 0 at its lowest point. Units: metres, radians, kilograms. Quaternions are (w, x, y, z).

Sign rule (all categories): a joint's ``axis`` is oriented so that increasing the state OPENS the part
(right-hand rule for revolute joints, direction of travel for prismatic ones), and state 0 is the
closed/folded pose of the category. Limits are (lower, upper) with lower <= 0 <= upper.
"""

from __future__ import annotations

from collections.abc import Iterable
from dataclasses import dataclass, field
from typing import Literal

import numpy as np

JointType = Literal["revolute", "prismatic"]


@dataclass(frozen=True)
class Box:
    """An axis-aligned (in its own pose) box: ``half_size`` (3,) metres, pose in its link frame."""

    half_size: tuple[float, float, float]
    pos: tuple[float, float, float] = (0.0, 0.0, 0.0)
    quat: tuple[float, float, float, float] = (1.0, 0.0, 0.0, 0.0)
    color: tuple[float, float, float, float] = (0.7, 0.7, 0.7, 1.0)
    is_handle: bool = False


@dataclass(frozen=True)
class Cylinder:
    """A solid cylinder along its own x-axis (SAPIEN's convention): ``radius`` and ``half_length``
    metres, pose in its link frame."""

    radius: float
    half_length: float
    pos: tuple[float, float, float] = (0.0, 0.0, 0.0)
    quat: tuple[float, float, float, float] = (1.0, 0.0, 0.0, 0.0)
    color: tuple[float, float, float, float] = (0.7, 0.7, 0.7, 1.0)
    is_handle: bool = False


@dataclass(frozen=True)
class ConvexMesh:
    """The convex hull of ``vertices`` (each (3,), metres, link frame): rounded, chamfered and curved
    panels. Collision and visual shape are the same hull."""

    vertices: tuple[tuple[float, float, float], ...]
    color: tuple[float, float, float, float] = (0.7, 0.7, 0.7, 1.0)
    is_handle: bool = False


Shape = Cylinder | ConvexMesh
"""The non-box shapes a link may carry (``LinkSpec.shapes``)."""


@dataclass(frozen=True)
class LinkSpec:
    """A rigid part. ``density`` in kg/m^3 sets the mass from the shapes' volume. ``shapes`` holds
    the non-box geometry (empty for every category's default instances). A ``balanced`` part is
    counterweighted: gravity does not act on it (a sash window's balance holds the sash where it is
    put)."""

    name: str
    boxes: tuple[Box, ...]
    density: float = 300.0
    shapes: tuple[Shape, ...] = ()
    balanced: bool = False


@dataclass(frozen=True)
class JointSpec:
    """A 1-DoF joint between ``parent`` and ``child`` links (names), expressed in the parent frame."""

    name: str
    type: JointType
    parent: str
    child: str
    origin: tuple[float, float, float]  # a point on the axis (the pivot), parent frame, metres
    axis: tuple[float, float, float]  # unit direction, parent frame; +state opens
    limits: tuple[float, float]  # radians (revolute) or metres (prismatic)
    damping: float = 1.0
    friction: float = 0.05


@dataclass(frozen=True)
class ObjectSpec:
    """One instance of a category: a pure function of (category, instance_id).

    ``links[0]`` is the fixed base; a link's index in ``links`` is its part label. ``target_joint``
    is the joint a robot should open; ``grasp_link``/``grasp_point`` give where to grasp it (the
    handle centre or the far edge), in that link's frame.
    """

    category: str
    instance_id: int
    links: tuple[LinkSpec, ...]
    joints: tuple[JointSpec, ...]
    target_joint: str
    grasp_link: str
    grasp_point: tuple[float, float, float]
    params: dict = field(default_factory=dict, compare=False)  # the sampled shape parameters
    # outward normal of the object's front (the side a robot should stand at), object frame; every
    # procedural category faces -x
    front: tuple[float, float, float] = (-1.0, 0.0, 0.0)

    def link_index(self, name: str) -> int:
        for i, link in enumerate(self.links):
            if link.name == name:
                return i
        raise KeyError(f"no link named {name!r} in {self.category} #{self.instance_id}")

    def joint_index(self, name: str) -> int:
        for i, joint in enumerate(self.joints):
            if joint.name == name:
                return i
        raise KeyError(
            f"no joint named {name!r} in {self.category} #{self.instance_id}; "
            f"joints: {[j.name for j in self.joints]}"
        )

    def aabb(self) -> tuple[np.ndarray, np.ndarray]:
        """Axis-aligned bounds (min, max) of all shapes at state 0, object frame, metres."""
        from capt_env.objects.geometry import box_corners, shape_points

        pts = np.concatenate([box_corners(b) for link in self.links for b in link.boxes]
                             + [shape_points(s) for link in self.links for s in link.shapes])
        return pts.min(axis=0), pts.max(axis=0)


def hinged_door_object(category: str, instance_id: int, body: Iterable[Box], door: LinkSpec, hinge: JointSpec,
                       grasp_point: tuple[float, float, float], params: dict,
                       body_shapes: Iterable[Shape] = ()) -> ObjectSpec:
    """An instance made of a fixed body (``body`` boxes and ``body_shapes``, 400 kg/m^3) and one
    ``door`` link on the revolute joint ``hinge`` (body to door), which is the target;
    ``grasp_point`` is in the door's frame, metres (an oven, a washing machine, a cabinet door)."""
    if hinge.parent != "body" or hinge.child != door.name:
        raise ValueError(f"the hinge must join 'body' to {door.name!r}, "
                         f"got {hinge.parent!r} -> {hinge.child!r}")
    return ObjectSpec(
        category,
        instance_id,
        (LinkSpec("body", tuple(body), density=400.0, shapes=tuple(body_shapes)), door),
        (hinge,),
        target_joint=hinge.name,
        grasp_link=door.name,
        grasp_point=grasp_point,
        params=params,
    )
