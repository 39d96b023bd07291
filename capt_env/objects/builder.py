"""Build an ``ObjectSpec`` into a ManiSkill scene as an articulation (boxes, cylinders and convex
meshes -> the same collision and visual shape each).

The simulator's joint axis is the x-axis of the joint frame, so each joint frame is placed at the
spec's ``origin`` with the rotation taking +x onto the spec's ``axis``; since the child frame equals
the parent frame at state 0, the same pose serves as ``pose_in_parent`` and ``pose_in_child``.
Joint damping is set through the builder (PhysX drive with stiffness 0); friction is set after
``build()`` because ManiSkill ignores it at build time.

Self-collisions between the object's own links are disabled (collision group 2, bit
``SELF_COLLISION_BIT``): moving parts of these objects only need to touch the robot, and e.g. the
two folded temples of eyeglasses would otherwise block each other.
"""

from __future__ import annotations

from typing import Any

import numpy as np
import sapien
import sapien.physx as physx
from mani_skill.utils.structs import Articulation

from capt_env.objects.geometry import quat_from_x_to
from capt_env.objects.mesh_files import convex_mesh_file
from capt_env.objects.spec import ConvexMesh, Cylinder, LinkSpec, ObjectSpec

SELF_COLLISION_BIT = 27
"""Bit of collision group 2 shared by all links of an object built here (no self-collision)."""

HANDLE_FRICTION = (1.0, 0.9, 0.0)  # static, dynamic, restitution of handle surfaces
BODY_FRICTION = (0.5, 0.4, 0.0)


def _pose(origin: np.ndarray, axis: np.ndarray) -> sapien.Pose:
    return sapien.Pose(p=[float(v) for v in origin], q=[float(v) for v in quat_from_x_to(axis)])


def build_articulated_object(
    scene: Any,
    spec: ObjectSpec,
    name: str,
    fix_root: bool = True,
    scale: float = 1.0,
    pose: sapien.Pose | None = None,
    scene_idxs: list[int] | None = None,
) -> Articulation:
    """Build ``spec`` into ``scene`` (a ``ManiSkillScene``) and return the articulation.

    :param name: articulation name, unique in the scene; link and joint names are the spec's.
    :param fix_root: weld the base link to the world.
    :param scale: uniform scale of all lengths (boxes, joint origins, prismatic limits); densities
        are kept, so masses scale with scale**3.
    :param pose: root pose in the world (default: identity, so the object frame is the world frame).
    :param scene_idxs: the sub-scenes to build it in (default: every sub-scene); ManiSkill's way to
        put a different object in each sub-scene (one build per sub-scene, then ``Articulation.merge``).
    """
    if scale <= 0:
        raise ValueError(f"scale must be > 0, got {scale}")
    can_render = scene.can_render()
    handle_mat = physx.PhysxMaterial(*HANDLE_FRICTION)
    body_mat = physx.PhysxMaterial(*BODY_FRICTION)

    builder = scene.create_articulation_builder()
    builder.set_name(name)
    if scene_idxs is not None:
        builder.set_scene_idxs(list(scene_idxs))
    builder.initial_pose = pose if pose is not None else sapien.Pose()
    link_builders: dict[str, Any] = {}
    joint_of_child = {j.child: j for j in spec.joints}
    for index, link in enumerate(spec.links):
        if index == 0:
            lb = builder.create_link_builder()
        else:
            joint = joint_of_child.get(link.name)
            if joint is None or joint.parent not in link_builders:
                raise ValueError(
                    f"link {link.name!r} of {spec.category} #{spec.instance_id} needs a joint from an "
                    "earlier link (links must be listed parents first)"
                )
            lb = builder.create_link_builder(link_builders[joint.parent])
            frame = _pose(np.asarray(joint.origin) * scale, np.asarray(joint.axis))
            limits = np.asarray(joint.limits, dtype=np.float64)
            if joint.type == "prismatic":
                limits = limits * scale
            lb.set_joint_name(joint.name)
            lb.set_joint_properties(
                joint.type, [limits.tolist()], frame, frame, friction=joint.friction, damping=joint.damping
            )
        lb.set_name(link.name)
        lb.collision_groups[2] |= 1 << SELF_COLLISION_BIT
        for box in link.boxes:
            half = [float(v) * scale for v in box.half_size]
            box_pose = sapien.Pose(p=[float(v) * scale for v in box.pos], q=list(box.quat))
            lb.add_box_collision(
                pose=box_pose,
                half_size=half,
                density=link.density,
                material=handle_mat if box.is_handle else body_mat,
            )
            if can_render:
                material = sapien.render.RenderMaterial(base_color=list(box.color), roughness=0.6)
                lb.add_box_visual(pose=box_pose, half_size=half, material=material)
        _add_shapes(lb, link, scale, can_render, handle_mat, body_mat)
        link_builders[link.name] = lb

    art = builder.build(name=name, fix_root_link=fix_root)
    if not scene.gpu_sim_enabled:
        # CPU: place the links now, so link and joint poses are valid before the first step
        art.set_root_pose(pose if pose is not None else sapien.Pose())  # a sapien.Pose: every sub-scene
    for link in spec.links:
        if link.balanced:
            art.links_map[link.name].disable_gravity = True
    for joint in spec.joints:
        sim_joint = art.joints_map[joint.name]
        sim_joint.set_friction(joint.friction)
        sim_joint.set_drive_properties(stiffness=0.0, damping=joint.damping)
    return art


def _add_shapes(lb: Any, link: LinkSpec, scale: float, can_render: bool, handle_mat: Any,
                body_mat: Any) -> None:
    """Add ``link.shapes`` (cylinders, convex meshes) to link builder ``lb``: collision and visual."""
    for shape in link.shapes:
        material = handle_mat if shape.is_handle else body_mat
        look = None  # a render material needs a render system
        if can_render:
            look = sapien.render.RenderMaterial(base_color=list(shape.color), roughness=0.6)
        if isinstance(shape, Cylinder):
            pose = sapien.Pose(p=[float(v) * scale for v in shape.pos], q=list(shape.quat))
            radius, half_length = float(shape.radius) * scale, float(shape.half_length) * scale
            lb.add_cylinder_collision(pose=pose, radius=radius, half_length=half_length, density=link.density,
                                      material=material)
            if can_render:
                lb.add_cylinder_visual(pose=pose, radius=radius, half_length=half_length, material=look)
        elif isinstance(shape, ConvexMesh):
            path = convex_mesh_file(shape.vertices)
            lb.add_convex_collision_from_file(path, scale=[scale] * 3, density=link.density,
                                              material=material)
            if can_render:
                lb.add_visual_from_file(path, scale=[scale] * 3, material=look)
        else:
            raise TypeError(f"unknown shape {type(shape).__name__} on link {link.name!r}")


def joint_world_axis(articulation: Articulation, joint_name: str) -> tuple[np.ndarray, np.ndarray]:
    """World-frame (direction (3,), pivot (3,)) of a joint of a single-scene articulation, from the
    simulator's current state: the joint frame's x-axis and origin."""
    if joint_name not in articulation.joints_map:
        raise KeyError(f"no joint {joint_name!r}; joints: {list(articulation.joints_map)}")
    mat = articulation.joints_map[joint_name].get_global_pose().to_transformation_matrix()
    mat = np.asarray(mat.reshape(-1, 4, 4)[0].cpu(), dtype=np.float64)
    return mat[:3, 0].copy(), mat[:3, 3].copy()


def link_segmentation_ids(articulation: Articulation) -> dict[str, int]:
    """Map link name -> the per-scene segmentation id the cameras report for that link."""
    return {link.name: int(link.per_scene_id.reshape(-1)[0]) for link in articulation.links}
