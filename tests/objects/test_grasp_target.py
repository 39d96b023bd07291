"""The ground-truth grasp target of a user file's moving part: handles by name and by geometry."""

from __future__ import annotations

import numpy as np
import pytest
import trimesh

from capt_env.objects.errors import ObjectFileError
from capt_env.objects.link_geometry import ShapeMesh
from capt_env.tasks.grasp_target import find_grasp_target, outward_normal

Z = np.array([0.0, 0.0, 1.0])


def box(name: str, centre: tuple[float, float, float], size: tuple[float, float, float]) -> ShapeMesh:
    mesh = trimesh.creation.box(extents=size)
    mesh.apply_translation(centre)
    return ShapeMesh(name, np.asarray(mesh.vertices), np.asarray(mesh.faces))


def door_panel(x_front: float = 0.0) -> ShapeMesh:
    """A 40 cm wide, 50 cm tall, 2 cm thick door whose outer face is at x = x_front, hinge at y = 0."""
    return box("panel", (x_front + 0.01, 0.2, 0.25), (0.02, 0.4, 0.5))


def find(meshes: list[ShapeMesh], axis: np.ndarray = Z, pivot=(0.0, 0.0, 0.0), revolute: bool = True,
         centre=(0.3, 0.2, 0.25), **kw):
    return find_grasp_target(meshes, ["door"] * len(meshes), axis, np.asarray(pivot, float), revolute,
                             np.asarray(centre, float), part_name="door", **kw)


def test_bar_handle_on_a_door_is_found_by_geometry() -> None:
    # A vertical bar 3 cm in front of the panel near the free edge, on two posts.
    meshes = [door_panel(), box("m1", (-0.04, 0.35, 0.25), (0.015, 0.015, 0.16)),
              box("m2", (-0.02, 0.35, 0.19), (0.03, 0.01, 0.01)),
              box("m3", (-0.02, 0.35, 0.31), (0.03, 0.01, 0.01))]
    # The door opens by turning about +z at y = 0 (its free edge at +y swings towards -x).
    target = find(meshes)
    assert target.source == "geometry"
    assert np.allclose(target.outward, [-1, 0, 0], atol=0.02)  # the handle tilts the panel fit a little
    assert np.linalg.norm(target.point - [-0.045, 0.35, 0.25]) < 0.01


def test_a_thick_bar_at_the_end_of_a_wide_door_is_grasped_not_the_panel_end_its_tilt_lifts() -> None:
    # Franka Kitchen's microwave: a 52 cm door, 5 cm thick, and a 4 cm bar standing 6 cm off its
    # far end. The whole door's least spread leans a few degrees towards the bar, which lifts the
    # panel's far half off the face level in a piece larger than the bar; the bar stands farther.
    meshes = [box("panel", (0.025, 0.26, 0.0), (0.05, 0.52, 0.37)),
              box("bar", (-0.06, 0.475, 0.0), (0.04, 0.04, 0.26)),
              box("post1", (-0.025, 0.475, 0.12), (0.05, 0.02, 0.02)),
              box("post2", (-0.025, 0.475, -0.12), (0.05, 0.02, 0.02))]
    target = find(meshes, centre=(0.2, 0.26, 0.0))
    assert target.source == "geometry" and abs(target.point[1] - 0.475) < 0.01 and target.point[0] < -0.06


def test_knob_is_found() -> None:
    meshes = [door_panel(), box("m1", (-0.02, 0.36, 0.3), (0.025, 0.025, 0.025))]
    target = find(meshes)
    # in the knob (x from -0.0325 to -0.0075), about its middle: the fingers close round it
    assert np.linalg.norm(target.point[1:] - [0.36, 0.3]) < 0.01 and -0.026 < target.point[0] < -0.014


def test_a_thick_round_bar_is_grasped_at_its_middle_not_its_front() -> None:
    # Meta-World's lever door: a round bar 4.6 cm thick, 12 cm out on a stem. Centred on the bar's
    # outermost 1.5 cm, the fingers close 1.6 cm in front of its axis and squeeze it out; the grip
    # is half the bar's thickness behind its front, on the axis.
    bar = trimesh.creation.cylinder(radius=0.023, height=0.15, sections=48)
    bar.apply_transform(trimesh.transformations.rotation_matrix(np.pi / 2, [1.0, 0.0, 0.0]))
    bar.apply_translation((-0.12, 0.3, 0.25))
    meshes = [door_panel(), ShapeMesh("bar", np.asarray(bar.vertices), np.asarray(bar.faces)),
              box("stem", (-0.05, 0.3, 0.25), (0.1, 0.026, 0.026))]
    target = find(meshes)
    assert target.source == "geometry"
    # the bar tilts the panel's fitted normal 3 deg along the bar, which moves the grip along it
    assert abs(target.point[0] + 0.12) < 0.008 and abs(target.point[2] - 0.25) < 0.005
    assert abs(target.point[1] - 0.3) < 0.02


def test_a_thin_bar_is_grasped_at_its_middle_too() -> None:
    # a 1 cm bar lies wholly inside the outermost layer: its middle is the layer's own middle
    meshes = [door_panel(), box("bar", (-0.045, 0.35, 0.25), (0.01, 0.01, 0.16)),
              box("post1", (-0.02, 0.35, 0.19), (0.04, 0.01, 0.01)),
              box("post2", (-0.02, 0.35, 0.31), (0.04, 0.01, 0.01))]
    target = find(meshes)
    assert np.linalg.norm(target.point - [-0.045, 0.35, 0.25]) < 0.004


def test_lever_standing_12cm_off_the_panel_is_found() -> None:
    # A stem 12 cm long, then a horizontal lever bar: the grasp is on the bar, not the bare panel.
    meshes = [door_panel(), box("stem", (-0.06, 0.35, 0.25), (0.12, 0.015, 0.015)),
              box("bar", (-0.125, 0.3, 0.25), (0.02, 0.12, 0.02))]
    target = find(meshes)
    assert target.source == "geometry"
    assert target.point[0] < -0.11
    assert abs(target.point[2] - 0.25) < 0.01
    assert 0.11 < target.standoff < 0.14  # how far the grip stands off the face, for inspect-object


def test_a_named_handle_wins_over_geometry() -> None:
    meshes = [door_panel(), box("knob", (-0.03, 0.1, 0.1), (0.02, 0.02, 0.02)),
              box("trim", (-0.03, 0.35, 0.4), (0.05, 0.05, 0.05))]
    target = find(meshes)
    assert target.source == "name" and np.linalg.norm(target.point[1:] - [0.1, 0.1]) < 0.01


def test_handle_option_names_a_geom_and_a_wrong_name_lists_the_names() -> None:
    meshes = [door_panel(), box("trim", (-0.03, 0.35, 0.4), (0.05, 0.05, 0.05))]
    assert find(meshes, handle="trim").source == "option"
    with pytest.raises(ObjectFileError, match="trim"):
        find(meshes, handle="nothing")


def test_two_doors_with_one_handle_each_grasp_their_own() -> None:
    # Each door is its own part; the right door (hinge at y = 0.8, opening about -z) holds the
    # handle near its free edge at y = 0.45, the left one near y = 0.35.
    right = [box("panel", (0.01, 0.6, 0.25), (0.02, 0.4, 0.5)),
             box("m", (-0.03, 0.45, 0.25), (0.02, 0.02, 0.12))]
    left = [door_panel(), box("m", (-0.03, 0.35, 0.25), (0.02, 0.02, 0.12))]
    t_right = find(right, axis=-Z, pivot=(0.0, 0.8, 0.0), centre=(0.3, 0.4, 0.25))
    t_left = find(left, centre=(0.3, 0.4, 0.25))
    assert abs(t_right.point[1] - 0.45) < 0.01 and abs(t_left.point[1] - 0.35) < 0.01


def test_bare_door_is_grasped_at_the_middle_of_its_free_edge() -> None:
    target = find([door_panel()])
    assert target.source == "edge"
    assert target.point[1] > 0.38 and abs(target.point[2] - 0.25) < 0.02 and abs(target.point[0]) < 0.006


def test_drawer_faces_along_its_slide_and_a_window_faces_out_of_its_plane() -> None:
    # Drawer: an open box 30 cm deep sliding towards -x; its front panel lies across the slide.
    from capt_env.objects.link_geometry import sample_surface

    drawer = [box("front", (0.0, 0.0, 0.08), (0.02, 0.4, 0.16)),
              box("bottom", (0.15, 0.0, 0.005), (0.3, 0.4, 0.01)),
              box("side1", (0.15, -0.2, 0.06), (0.3, 0.01, 0.12)),
              box("side2", (0.15, 0.2, 0.06), (0.3, 0.01, 0.12))]
    pts, _ = sample_surface(drawer, 3000)
    normal = outward_normal(pts, np.array([-1.0, 0, 0]), np.zeros(3), False, np.array([0.2, 0, 0.2]))
    assert np.allclose(normal, [-1, 0, 0])
    # Window: a panel in the x = 0 plane of its frame, sliding up (+z); the frame's centre is behind it.
    panel = box("glass", (0.0, 0.0, 0.3), (0.01, 0.5, 0.4))
    pts, _ = sample_surface([panel], 3000)
    normal = outward_normal(pts, Z, np.zeros(3), False, np.array([0.05, 0, 0.4]))
    assert np.allclose(normal, [-1, 0, 0], atol=1e-3)
