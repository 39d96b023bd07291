"""Surface geometry of a built link, from its render shapes, in the link's own frame (metres).

Written by hand because ManiSkill's ``trimesh_utils`` builds cylinder and capsule meshes along z
while SAPIEN's primitives lie along x, which turns every cylinder and capsule by 90 degrees; here
each primitive's unit mesh (SAPIEN's own vertices) is scaled by its sizes, so the geometry is
exactly what the cameras see (and collision shapes likewise). Links without any shape (frames for
a latch or a handle) give empty arrays instead of failing.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
import sapien.render as sr
import trimesh


@dataclass(frozen=True)
class ShapeMesh:
    """One render shape as a triangle mesh in the link frame (metres)."""

    name: str
    vertices: np.ndarray  # (V, 3)
    faces: np.ndarray  # (F, 3) int


def _pose_matrix(pose: object) -> np.ndarray:
    return np.asarray(pose.to_transformation_matrix(), dtype=np.float64)


def _capsule_along_x(radius: float, half_length: float) -> tuple[np.ndarray, np.ndarray]:
    return _along_x(trimesh.creation.capsule(height=2 * half_length, radius=radius, count=[12, 12]))


def shape_meshes(shape: sr.RenderShape) -> list[ShapeMesh]:
    """The meshes of one render shape in its link's frame; planes give none."""
    name = shape.name or ""
    if isinstance(shape, sr.RenderShapeTriangleMesh):
        parts = [(np.asarray(p.vertices, dtype=np.float64) * np.asarray(shape.scale), np.asarray(p.triangles))
                 for p in shape.parts]
    elif isinstance(shape, sr.RenderShapeBox):
        parts = [(np.asarray(shape.vertices) * np.asarray(shape.half_size), np.asarray(shape.triangles))]
    elif isinstance(shape, sr.RenderShapeCylinder):  # unit cylinder along x
        size = np.array([shape.half_length, shape.radius, shape.radius])
        parts = [(np.asarray(shape.vertices) * size, np.asarray(shape.triangles))]
    elif isinstance(shape, sr.RenderShapeCapsule):  # SAPIEN capsules lie along x
        parts = [_capsule_along_x(float(shape.radius), float(shape.half_length))]
    elif isinstance(shape, sr.RenderShapeSphere):
        parts = [(np.asarray(shape.vertices) * float(shape.radius), np.asarray(shape.triangles))]
    else:  # planes and anything unbounded
        return []
    mat = _pose_matrix(shape.local_pose)
    out = []
    for verts, faces in parts:
        verts = np.asarray(verts, dtype=np.float64).reshape(-1, 3)
        out.append(ShapeMesh(name=name, vertices=verts @ mat[:3, :3].T + mat[:3, 3],
                             faces=np.asarray(faces, dtype=np.int64).reshape(-1, 3)))
    return out


def _along_x(mesh: trimesh.Trimesh) -> tuple[np.ndarray, np.ndarray]:
    mesh.apply_transform(trimesh.transformations.rotation_matrix(np.pi / 2, [0, 1, 0]))  # z -> x
    return np.asarray(mesh.vertices), np.asarray(mesh.faces)


def collision_shape_meshes(link: object) -> list[ShapeMesh]:
    """Every collision shape of a ManiSkill ``Link`` (first sub-scene) as a mesh in the link frame;
    PhysX capsules and cylinders lie along x, as the render shapes do."""
    import sapien.physx as px

    out = []
    for shape in link._objs[0].get_collision_shapes():
        if isinstance(shape, px.PhysxCollisionShapeBox):
            mesh = trimesh.creation.box(extents=2 * np.asarray(shape.half_size))
            verts, faces = np.asarray(mesh.vertices), np.asarray(mesh.faces)
        elif isinstance(shape, px.PhysxCollisionShapeCapsule):
            verts, faces = _capsule_along_x(float(shape.radius), float(shape.half_length))
        elif isinstance(shape, px.PhysxCollisionShapeCylinder):
            verts, faces = _along_x(trimesh.creation.cylinder(radius=float(shape.radius),
                                                              height=2 * float(shape.half_length)))
        elif isinstance(shape, px.PhysxCollisionShapeSphere):
            mesh = trimesh.creation.icosphere(radius=float(shape.radius), subdivisions=2)
            verts, faces = np.asarray(mesh.vertices), np.asarray(mesh.faces)
        elif isinstance(shape, (px.PhysxCollisionShapeConvexMesh, px.PhysxCollisionShapeTriangleMesh)):
            verts = np.asarray(shape.vertices, dtype=np.float64) * np.asarray(shape.scale)
            faces = np.asarray(shape.get_triangles())
        else:  # planes
            continue
        mat = _pose_matrix(shape.local_pose)
        verts = np.asarray(verts) @ mat[:3, :3].T + mat[:3, 3]
        out.append(ShapeMesh("", verts, np.asarray(faces).reshape(-1, 3)))
    return out


def link_shape_meshes(link: object) -> list[ShapeMesh]:
    """Every render shape of a ManiSkill ``Link`` (first sub-scene) as meshes in the link frame."""
    shapes = link.render_shapes
    first = shapes[0] if shapes and isinstance(shapes[0], list) else shapes
    return [m for shape in first for m in shape_meshes(shape)]


def link_vertices(link: object) -> np.ndarray:
    """(V, 3) vertices of all a link's render shapes in the link frame; (0, 3) for a bare frame."""
    meshes = link_shape_meshes(link)
    if not meshes:
        return np.zeros((0, 3))
    return np.concatenate([m.vertices for m in meshes])


def sample_surface(meshes: list[ShapeMesh], count: int, seed: int = 0) -> tuple[np.ndarray, np.ndarray]:
    """``count`` points spread over the meshes' surfaces by area (deterministic for a seed), and the
    index of the mesh each lies on. Empty input gives empty arrays."""
    meshes = [m for m in meshes if len(m.faces)]
    if not meshes:
        return np.zeros((0, 3)), np.zeros(0, dtype=np.int64)
    tris = [m.vertices[m.faces] for m in meshes]  # (F, 3, 3) each
    areas = [0.5 * np.linalg.norm(np.cross(t[:, 1] - t[:, 0], t[:, 2] - t[:, 0]), axis=1) for t in tris]
    all_tris = np.concatenate(tris)
    all_areas = np.concatenate(areas)
    owner = np.concatenate([np.full(len(t), k) for k, t in enumerate(tris)])
    total = float(all_areas.sum())
    if total <= 0:
        verts = np.concatenate([m.vertices for m in meshes])
        return verts, np.concatenate([np.full(len(m.vertices), k) for k, m in enumerate(meshes)])
    rng = np.random.default_rng(seed)
    pick = rng.choice(len(all_tris), size=count, p=all_areas / total)
    u, v = rng.random(count), rng.random(count)
    flip = u + v > 1
    u[flip], v[flip] = 1 - u[flip], 1 - v[flip]
    t = all_tris[pick]
    pts = t[:, 0] + u[:, None] * (t[:, 1] - t[:, 0]) + v[:, None] * (t[:, 2] - t[:, 0])
    return pts, owner[pick]
