"""The grasp finder on synthetic clouds: a closed door in the plane x = -0.2 (y in [-0.2, 0.2], z in
[0, 0.4]) facing -x, the robot's side, on a carcass behind it (its top and its side walls just inside
the door's edges), with bars of any orientation, a lever, a knob, a recessed pull, two bars of a
double door, nothing, or stray points in front of it. World frame, metres."""

from __future__ import annotations

from types import SimpleNamespace

import numpy as np
import pytest

from capt_common.typed_yaml import ConfigError
from capt_env.wrappers.grasp_candidates import GraspCandidateConfig, clusters, find_grasp_candidates
from capt_env.wrappers.moving_part_geometry import handle_point
from capt_env.wrappers.refiners.draft import network_draft
from capt_env.wrappers.refiners.handle import Handle
from perception.inference import ArticulationEstimate, JointEstimate

FACE_X = -0.2
OUT = np.array([-1.0, 0.0, 0.0])
Y, Z = np.array([0.0, 1.0, 0.0]), np.array([0.0, 0.0, 1.0])


def _door(rng: np.random.Generator, hole: tuple[float, float, float, float] | None = None) -> np.ndarray:
    """The door's face (1,600 points, 1 mm noise), without the points inside ``hole`` = (y0, y1, z0, z1)."""
    door = np.column_stack([np.full(1600, FACE_X), rng.uniform(-0.2, 0.2, 1600), rng.uniform(0.0, 0.4, 1600)])
    if hole is not None:
        y0, y1, z0, z1 = hole
        door = door[~((door[:, 1] > y0) & (door[:, 1] < y1) & (door[:, 2] > z0) & (door[:, 2] < z1))]
    return door + rng.normal(0.0, 0.001, door.shape)


def _carcass(rng: np.random.Generator) -> np.ndarray:
    """The carcass behind the door: its top (z = 0.42) and side walls (y = +-0.195, inside the door's
    extent seen from the front, so behind the face there are points 0-40 cm deep at its edges)."""
    top = np.column_stack([rng.uniform(-0.2, 0.2, 400), rng.uniform(-0.2, 0.2, 400), np.full(400, 0.42)])
    sides = np.column_stack([rng.uniform(-0.195, 0.2, 400), np.repeat([-0.195, 0.195], 200),
                             rng.uniform(0.0, 0.4, 400)])
    return np.concatenate([top, sides])


def _bar(rng: np.random.Generator, centre: np.ndarray, axis: np.ndarray, length: float = 0.12,
         n: int = 60) -> np.ndarray:
    """A bar of ``length`` m along unit ``axis`` about ``centre`` (its front face, 3 mm noise across)."""
    t = rng.uniform(-0.5 * length, 0.5 * length, n)
    return centre + np.outer(t, axis) + rng.normal(0.0, 0.003, (n, 3)) * np.array([0.3, 1.0, 1.0])


def _posts(rng: np.random.Generator, feet: list[np.ndarray], standoff: float, n: int = 10) -> np.ndarray:
    """Posts (1 cm thick) from the face out to ``standoff`` m at each foot (3,) on the face."""
    return np.concatenate([foot + np.outer(rng.uniform(0.0, standoff, n), OUT)
                           + rng.normal(0.0, 0.003, (n, 3)) * np.array([0.0, 1.0, 1.0]) for foot in feet])


def _scene(rng: np.random.Generator, *extra: np.ndarray,
           hole: tuple[float, float, float, float] | None = None) -> tuple[np.ndarray, np.ndarray]:
    """(object points, the door's points as segmented: its face and whatever stands on it)."""
    door = np.concatenate([_door(rng, hole), *extra]) if extra else _door(rng, hole)
    return np.concatenate([door, _carcass(rng)]), door


def _at(standoff: float, y: float, z: float) -> np.ndarray:
    return np.array([FACE_X - standoff, y, z])


def _kinds(found) -> list[str]:
    return [g.kind for g in found]


@pytest.mark.parametrize("axis", [Y, Z, (Y + Z) / np.sqrt(2.0)], ids=["horizontal", "vertical", "diagonal"])
def test_a_bar_of_any_orientation_is_found_with_its_axis(axis: np.ndarray) -> None:
    rng = np.random.default_rng(0)
    centre = _at(0.03, 0.08, 0.2)
    feet = [centre + 0.05 * axis - 0.03 * OUT, centre - 0.05 * axis - 0.03 * OUT]
    cloud, door = _scene(rng, _bar(rng, centre, axis), _posts(rng, feet, 0.03))
    found = find_grasp_candidates(cloud, door)
    assert _kinds(found) == ["bar", "edge"]
    bar = found[0]
    np.testing.assert_allclose(bar.point, centre, atol=0.01)
    assert abs(float(bar.bar_axis @ axis)) > np.cos(np.radians(5.0))
    np.testing.assert_allclose(bar.outward, OUT, atol=0.01)
    assert abs(float(bar.closing @ axis)) < 0.1 and abs(float(bar.closing @ OUT)) < 0.01
    assert bar.width < 0.03  # its thickness, not its length: it fits the open gripper
    assert bar.clearance == pytest.approx(GraspCandidateConfig().corridor_radius)
    assert bar.score > found[1].score


def test_a_lever_eleven_cm_off_the_panel_is_a_bar_at_its_grip() -> None:
    rng = np.random.default_rng(1)
    grip = _at(0.11, 0.05, 0.25)  # a 10 cm horizontal lever on a post at y = 0.1
    lever, post = _bar(rng, grip, Y, length=0.1, n=50), _posts(rng, [_at(0.0, 0.1, 0.25)], 0.11, 20)
    cloud, door = _scene(rng, lever, post)
    old = handle_point(cloud, door)  # its 8 cm band sees only the post
    assert old is not None and np.linalg.norm(old - grip) > 0.04
    found = find_grasp_candidates(cloud, door)
    assert _kinds(found) == ["bar", "edge"]
    np.testing.assert_allclose(found[0].point, grip, atol=0.015)
    assert abs(float(found[0].bar_axis @ Y)) > np.cos(np.radians(10.0))


def test_a_round_knob_is_a_knob() -> None:
    rng = np.random.default_rng(2)
    centre = _at(0.035, -0.1, 0.2)
    angle, radius = rng.uniform(0.0, 2 * np.pi, 80), 0.015 * np.sqrt(rng.uniform(0.0, 1.0, 80))
    cap = centre + np.outer(radius * np.cos(angle), Y) + np.outer(radius * np.sin(angle), Z)
    cloud, door = _scene(rng, cap, _posts(rng, [_at(0.0, -0.1, 0.2)], 0.035))
    found = find_grasp_candidates(cloud, door)
    assert _kinds(found) == ["knob", "edge"]
    np.testing.assert_allclose(found[0].point, centre, atol=0.01)
    assert 0.02 < found[0].width < 0.04


def test_a_recessed_pull_is_a_pocket_behind_the_face() -> None:
    rng = np.random.default_rng(3)
    y0, y1, z0, z1, depth = 0.06, 0.09, 0.16, 0.24, 0.025  # 3 cm wide, 8 cm tall, 2.5 cm deep
    back = np.column_stack([np.full(150, FACE_X + depth), rng.uniform(y0, y1, 150), rng.uniform(z0, z1, 150)])
    wall = np.column_stack([FACE_X + rng.uniform(0.0, depth, 60), np.full(60, y0), rng.uniform(z0, z1, 60)])
    cloud, door = _scene(rng, back, wall, hole=(y0, y1, z0, z1))
    found = find_grasp_candidates(cloud, door)
    assert _kinds(found) == ["recess", "edge"]  # not the carcass's walls behind the door's edges
    pull = found[0]
    np.testing.assert_allclose(pull.point[1:], [0.5 * (y0 + y1), 0.5 * (z0 + z1)], atol=0.01)
    assert FACE_X < pull.point[0] < FACE_X + depth  # the fingertips go into the pocket
    assert abs(float(pull.bar_axis @ Z)) > 0.95 and pull.width < 0.04  # the fingers close across it


def test_two_bars_of_a_double_door_are_two_candidates_never_their_middle() -> None:
    rng = np.random.default_rng(4)
    left, right = _at(0.03, -0.08, 0.2), _at(0.03, 0.08, 0.2)
    cloud, door = _scene(rng, _bar(rng, left, Z), _bar(rng, right, Z))
    found = find_grasp_candidates(cloud, door)
    assert _kinds(found) == ["bar", "bar", "edge"]
    points = sorted((g.point for g in found[:2]), key=lambda p: p[1])
    for found_at, bar in zip(points, (left, right), strict=True):  # across each bar, and along it
        np.testing.assert_allclose(found_at[:2], bar[:2], atol=0.01)
        assert abs(found_at[2] - bar[2]) < 0.02
    assert all(abs(g.point[1]) > 0.05 for g in found[:2])  # nothing between the two handles
    assert abs(handle_point(cloud, door)[1]) < 0.02  # the old single centroid falls between them


def test_the_handle_refiner_grasps_one_bar_of_a_double_door() -> None:
    rng = np.random.default_rng(4)
    left, right = _at(0.03, -0.08, 0.2), _at(0.03, 0.08, 0.2)
    cloud, door = _scene(rng, _bar(rng, left, Z), _bar(rng, right, Z))
    labels = np.r_[np.ones(len(door), int), np.zeros(len(cloud) - len(door), int)]
    hinge = JointEstimate(0, "revolute", Z, np.array([FACE_X, -0.2, 0.2]), 0.0, 0.9)
    draft = network_draft(ArticulationEstimate(labels, (hinge,), 0.0), cloud, 0,
                          SimpleNamespace(joint_child_parts=(1,), joint_types=("revolute",)))
    assert Handle().refine(draft) and draft.from_handle and draft.grasp is not None
    assert min(np.linalg.norm(draft.grasp - left), np.linalg.norm(draft.grasp - right)) < 0.02


def test_a_bare_panel_offers_only_its_free_edge() -> None:
    rng = np.random.default_rng(5)
    cloud, door = _scene(rng)
    found = find_grasp_candidates(cloud, door, hinge_direction=Z, hinge_pivot=np.array([FACE_X, -0.2, 0.2]))
    assert _kinds(found) == ["edge"]
    edge = found[0]
    np.testing.assert_allclose(edge.point, [FACE_X, 0.2 - 0.02, 0.2], atol=0.015)  # away from the hinge
    assert abs(float(edge.bar_axis @ Z)) > 0.99 and edge.width == 0.0
    other = find_grasp_candidates(cloud, door, hinge_direction=Z, hinge_pivot=np.array([FACE_X, 0.2, 0.2]))
    assert other[0].point[1] < -0.15
    assert _kinds(find_grasp_candidates(cloud, door)) == ["edge"]  # no hinge: the longest axis's end


def test_stray_points_in_front_of_the_door_make_no_candidate() -> None:
    rng = np.random.default_rng(6)
    stray = np.column_stack([FACE_X - rng.uniform(0.012, 0.14, 15), rng.uniform(-0.2, 0.2, 15),
                             rng.uniform(0.0, 0.4, 15)])
    cloud, door = _scene(rng, stray)
    assert _kinds(find_grasp_candidates(cloud, door)) == ["edge"]
    centre = _at(0.03, 0.1, 0.3)
    cloud, door = _scene(rng, stray, _bar(rng, centre, Y))
    found = find_grasp_candidates(cloud, door)
    assert _kinds(found) == ["bar", "edge"]
    np.testing.assert_allclose(found[0].point, centre, atol=0.01)


def test_a_raised_panel_wider_than_a_hand_is_not_a_handle() -> None:
    rng = np.random.default_rng(7)
    slab = np.column_stack([np.full(300, FACE_X - 0.015), rng.uniform(-0.15, 0.15, 300),
                            rng.uniform(0.1, 0.3, 300)])
    cloud, door = _scene(rng, slab)
    assert _kinds(find_grasp_candidates(cloud, door)) == ["edge"]


def test_clearance_is_the_free_space_beside_the_approach() -> None:
    rng = np.random.default_rng(8)
    centre = _at(0.03, 0.0, 0.2)
    # a frame's rib standing 5 cm out, 4 cm beside the bar's line
    rib = np.column_stack([FACE_X - rng.uniform(0.01, 0.05, 80), np.full(80, 0.04),
                           rng.uniform(0.05, 0.35, 80)])
    cloud, door = _scene(rng, _bar(rng, centre, Z), rib)
    found = find_grasp_candidates(cloud, door, config=GraspCandidateConfig(link_radius=0.02))
    bar = next(g for g in found if g.kind == "bar" and abs(g.point[1]) < 0.01)
    assert bar.clearance == pytest.approx(0.04, abs=0.01)


def test_no_candidates_on_a_part_that_is_not_flat() -> None:
    blob = np.random.default_rng(9).normal(size=(300, 3)) * 0.1
    assert find_grasp_candidates(blob, blob) == []


def test_clusters_are_linked_points_with_small_groups_dropped() -> None:
    points = np.array([[0.0, 0, 0], [0.01, 0, 0], [0.02, 0, 0], [0.5, 0, 0], [0.51, 0, 0], [0.9, 0, 0]])
    groups = clusters(points, np.ones(6, bool), link_radius=0.015, min_points=2)
    assert [g.tolist() for g in groups] == [[0, 1, 2], [3, 4]]
    assert clusters(points, np.zeros(6, bool), 0.015, 1) == []


@pytest.mark.parametrize("bad", [{"min_standoff": 0.2}, {"link_radius": 0.0}, {"grip_share": 1.5},
                                 {"min_recess_depth": 0.06}, {"edge_quantile": 0.5}])
def test_the_config_rejects_impossible_thresholds(bad: dict) -> None:
    GraspCandidateConfig().validate()
    with pytest.raises(ConfigError):
        GraspCandidateConfig(**bad).validate()


def test_a_part_slides_across_an_upright_face_not_out_of_it_nor_along_a_floor() -> None:
    from capt_env.wrappers.moving_part_geometry import PartPlane, faces_along, facing, slides_across

    upright = PartPlane(np.zeros(3), np.array([[0.0, 1.0, 0.0], [0.0, 0.0, 1.0]]), np.array([-1.0, 0.0, 0.0]))
    floor = PartPlane(np.zeros(3), np.array([[1.0, 0.0, 0.0], [0.0, 1.0, 0.0]]), np.array([0.0, 0.0, 1.0]))
    for d in ([0.0, 0.0, 1.0], [0.0, 1.0, 0.0], [-0.3, 0.9, 0.0]):  # a sash: up, sideways, a bit out
        assert slides_across(upright, np.array(d)) and not faces_along(upright, np.array(d))
    assert faces_along(upright, np.array([-1.0, 0.0, 0.0]))
    assert not slides_across(upright, np.array([-1.0, 0.0, 0.0]))  # a drawer
    assert not slides_across(floor, np.array([1.0, 0.0, 0.0]))  # an open drawer's bottom
    assert not slides_across(None, np.array([0.0, 0.0, 1.0]))
    turned = facing(upright, np.array([1.0, 0.0, 0.5]))  # seen from behind: the normal turns round
    np.testing.assert_allclose(turned.outward, [1.0, 0.0, 0.0])
    assert facing(upright, np.array([-1.0, 0.0, 0.5])) is upright


def test_a_round_bar_on_long_posts_is_gripped_at_its_axis_not_at_its_seen_side() -> None:
    # a 1.6 cm round bar along y, its axis 7 cm off the face on two posts (Meta-World's window bar),
    # seen from level with it: the front 120 deg of its surface, and the posts
    rng = np.random.default_rng(3)
    radius, axis_at = 0.008, _at(0.07, 0.0, 0.2)
    t, a = rng.uniform(-0.06, 0.06, 300), rng.uniform(-np.pi / 3.0, np.pi / 3.0, 300)
    bar = axis_at + np.outer(t, Y) + radius * (np.outer(np.cos(a), OUT) + np.outer(np.sin(a), Z))
    posts = np.concatenate([_at(0.0, y, 0.2) + np.outer(rng.uniform(0.0, 0.07, 30), OUT)
                            + radius * rng.uniform(-1.0, 1.0, (30, 1)) * Z for y in (-0.045, 0.045)])
    cloud, door = _scene(rng, bar, posts)
    found = find_grasp_candidates(cloud, door)
    assert found[0].kind == "bar"
    assert abs(float((found[0].point - axis_at) @ OUT)) < 0.003  # half its thickness behind its front
    # the centroid of the bar's outer points sits on the seen side, in front of the axis
    from capt_env.wrappers.moving_part_geometry import PartPlane, bar_centre, outer_layer

    plane = PartPlane(np.array([FACE_X, 0.0, 0.2]), np.array([Y, Z]), OUT)
    out = cloud[((cloud - plane.centre) @ OUT > 0.01) & ((cloud - plane.centre) @ OUT < 0.15)]
    centroid = bar_centre(out[outer_layer(out, plane)], OUT)
    assert float((centroid - axis_at) @ OUT) > 0.004
