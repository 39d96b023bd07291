"""The flat joint-axis observation matches its documented layout, and encodes/decodes losslessly."""

from __future__ import annotations

import numpy as np

from capt_env.wrappers.estimate import JointAxisEstimate, canonical_pivot, grasp_point_of_part, unit
from capt_env.wrappers.joint_observation import (
    OBSERVATION_SIZE,
    build_dict,
    decode_observation,
    dict_space,
    flat_space,
    flatten,
    observation_layout,
)
from capt_env.wrappers.moving_part_geometry import (
    bar_centre,
    coplanar_panel,
    edge_aligned_direction,
    handle_point,
    hinge_on_edge,
    opening_direction,
    part_plane,
)


def _estimate() -> JointAxisEstimate:
    return JointAxisEstimate("prismatic", np.array([-1.0, 0.0, 0.0]), np.array([0.1, 0.2, 0.3]), 0.05,
                             np.array([0.0, 0.2, 0.3]), 0.8)


def test_layout_tiles_the_space_and_matches_the_docstring() -> None:
    layout = observation_layout()
    starts = sorted((s.start, s.stop) for s in layout.values())
    assert starts[0][0] == 0 and starts[-1][1] == OBSERVATION_SIZE
    assert all(a[1] == b[0] for a, b in zip(starts, starts[1:], strict=False))
    assert flat_space().shape == (OBSERVATION_SIZE,) and flat_space().dtype == np.float32
    import capt_env.wrappers.joint_observation as module

    for name, sl in layout.items():  # every row of the docstring table names the same slice
        assert f"{name} " in module.__doc__ and f"{sl.start}:{sl.stop}" in module.__doc__
        assert dict_space()[name].shape == (sl.stop - sl.start,)


def test_round_trip_through_flat_and_dict() -> None:
    qpos, qvel, tcp = np.arange(9.0), -np.arange(9.0), np.array([0.1, 0.2, 0.3, 1, 0, 0, 0])
    d = build_dict(qpos, qvel, tcp, _estimate())
    flat = flatten(d)
    assert flat_space().contains(flat) and dict_space().contains(d)
    layout = observation_layout()
    np.testing.assert_allclose(flat[layout["joint_type"]], [0.0, 1.0])
    np.testing.assert_allclose(flat[layout["qvel"]], qvel)
    for obs in (flat, d):
        proprio, est = decode_observation(obs)
        assert est.joint_type == "prismatic"
        np.testing.assert_allclose(est.pivot, [0.1, 0.2, 0.3], atol=1e-6)
        np.testing.assert_allclose(proprio["tcp_pose"], tcp, atol=1e-6)
        assert abs(est.confidence - 0.8) < 1e-6 and abs(est.state - 0.05) < 1e-6


def test_canonical_pivot_and_far_edge_grasp_point() -> None:
    u = np.array([0.0, 0.0, 1.0])
    np.testing.assert_allclose(canonical_pivot(u, np.zeros(3), np.array([0.3, 0.0, 0.5])), [0, 0, 0.5])
    rng = np.random.default_rng(0)
    door = np.stack([rng.uniform(0.0, 0.4, 2000), np.zeros(2000), rng.uniform(0.0, 0.5, 2000)], axis=1)
    g = grasp_point_of_part(door, "revolute", u, np.zeros(3))
    assert g[0] > 0.38  # the edge far from the hinge at x = 0
    g = grasp_point_of_part(door, "prismatic", np.array([1.0, 0.0, 0.0]), np.zeros(3))
    assert g[0] > 0.38


def test_far_edge_grasp_point_finds_a_lids_lip() -> None:
    # a closed lid (x in [-0.23, 0], y in [-0.15, 0.15], hinge along y at x = 0) with a 6 cm lip
    # overhanging its front edge by 2 cm at y in [0.05, 0.11]; points uniform by area
    rng = np.random.default_rng(1)
    lid = np.stack([rng.uniform(-0.23, 0.0, 1000), rng.uniform(-0.15, 0.15, 1000), np.zeros(1000)], axis=1)
    lip = np.stack([rng.uniform(-0.25, -0.23, 17), rng.uniform(0.05, 0.11, 17), np.zeros(17)], axis=1)
    g = grasp_point_of_part(np.concatenate([lid, lip]), "revolute", np.array([0.0, 1.0, 0.0]), np.zeros(3))
    assert abs(g[1] - 0.08) < 0.02, g  # on the lip, not the middle of the front edge
    assert g[0] < -0.235


def _oven_like_scene(rng: np.random.Generator, with_handle: bool) -> tuple[np.ndarray, np.ndarray]:
    """A door in the plane x = 0 (y in [-0.2, 0.2], z in [0, 0.4]) on a body behind it (x > 0), and
    optionally a bar handle 3 cm in front of the door (x = -0.03) at z = 0.35, y in [-0.1, 0.1]."""
    door = np.stack([np.zeros(800), rng.uniform(-0.2, 0.2, 800), rng.uniform(0.0, 0.4, 800)], axis=1)
    body = np.stack([rng.uniform(0.02, 0.4, 800), rng.uniform(-0.2, 0.2, 800), np.full(800, 0.45)], axis=1)
    parts = [door, body]
    if with_handle:
        parts.append(np.stack([np.full(40, -0.03), rng.uniform(-0.1, 0.1, 40), np.full(40, 0.35)], axis=1))
    return np.concatenate(parts), door


def test_handle_point_finds_the_bar_in_front_of_the_door_plane() -> None:
    rng = np.random.default_rng(1)
    cloud, door = _oven_like_scene(rng, with_handle=True)
    h = handle_point(cloud, door[door[:, 1] < 0])  # a segmentation that labels only half the door
    assert h is not None
    np.testing.assert_allclose(h, [-0.03, 0.0, 0.35], atol=0.02)
    # no handle: nothing stands off the outer side (the body lies behind the door)
    cloud, door = _oven_like_scene(rng, with_handle=False)
    assert handle_point(cloud, door) is None
    # a part that is not flat has no plane to stand off
    blob = rng.normal(size=(200, 3)) * 0.1
    assert handle_point(blob, blob) is None


def test_handle_point_survives_mislabelled_body_points_surface_noise_and_uneven_density() -> None:
    rng = np.random.default_rng(2)
    door = np.stack([np.zeros(800), rng.uniform(-0.2, 0.2, 800), rng.uniform(0.0, 0.4, 800)], axis=1)
    body = np.stack([rng.uniform(0.02, 0.4, 800), rng.uniform(-0.2, 0.2, 800), np.full(800, 0.45)], axis=1)
    # surface noise: a patch of the door's lower half just above min_standoff (1.3 cm) off its plane
    bump = np.stack([np.full(60, -0.013), rng.uniform(-0.2, 0.2, 60), rng.uniform(0.0, 0.15, 60)], axis=1)
    # the bar (y in [-0.1, 0.1]) seen densely on one side only, as when the hand hides the other side
    bar_y = np.concatenate([rng.uniform(-0.1, 0.0, 60), rng.uniform(0.0, 0.1, 8)])
    bar = np.stack([np.full(len(bar_y), -0.03), bar_y, np.full(len(bar_y), 0.35)], axis=1)
    cloud = np.concatenate([door, body, bump, bar])
    part = np.concatenate([door, bump, body[:80]])  # a segmentation that also takes some of the body
    h = handle_point(cloud, part)
    assert h is not None
    np.testing.assert_allclose(h, [-0.03, 0.0, 0.35], atol=0.02)


def test_bar_centre_of_a_bar_seen_from_above_is_the_middle_of_its_thickness() -> None:
    # a 2 cm square bar along y, centred at (-0.03, 0, 0.35) in front of a face whose outward normal is
    # -x, seen from above and in front: its top (z = 0.36, dense) and front (x = -0.04) faces only
    rng = np.random.default_rng(4)
    top = np.stack([rng.uniform(-0.04, -0.02, 300), rng.uniform(-0.1, 0.1, 300), np.full(300, 0.36)], axis=1)
    front = np.stack([np.full(100, -0.04), rng.uniform(-0.1, 0.1, 100), rng.uniform(0.34, 0.36, 100)], axis=1)
    bar = np.concatenate([top, front])
    centre = bar_centre(bar, np.array([-1.0, 0.0, 0.0]))
    np.testing.assert_allclose(centre[1:], [0.0, 0.35], atol=0.002)  # across the bar: its middle
    assert bar_centre(bar)[2] > 0.354  # the centroid sits on the seen top side


def test_a_door_in_a_bare_frame_faces_the_cameras_not_away_from_its_handle() -> None:
    # a door panel in the plane x = 0 between two frame posts, no body behind it, a lever standing
    # 10 cm out towards the cameras (at x < 0): the handle pulls the object's centroid in front of the
    # panel, which would turn the outward normal away from the cameras
    rng = np.random.default_rng(5)
    door = np.stack([np.zeros(600), rng.uniform(-0.2, 0.2, 600), rng.uniform(0.0, 0.6, 600)], axis=1)
    posts = np.stack([np.zeros(100), np.repeat([-0.25, 0.25], 50), rng.uniform(0.0, 0.6, 100)], axis=1)
    lever = np.stack([rng.uniform(-0.11, -0.09, 80), rng.uniform(0.05, 0.2, 80), np.full(80, 0.3)], axis=1)
    cloud = np.concatenate([door, posts, lever])
    cameras = np.array([-0.8, 0.0, 0.6])
    seen = part_plane(cloud, door, viewpoint=cameras)
    assert seen is not None and seen.outward[0] < -0.99
    assert part_plane(cloud, door).outward[0] > 0.99  # the away-from-the-centroid rule alone
    # with a body behind the door (a cabinet), the body decides even from behind
    body = np.stack([rng.uniform(0.05, 0.4, 600), rng.uniform(-0.2, 0.2, 600), rng.uniform(0.0, 0.6, 600)],
                    axis=1)
    cabinet = np.concatenate([door, body, lever])
    assert part_plane(cabinet, door, viewpoint=np.array([0.8, 0.0, 0.6])).outward[0] < -0.99


def test_opening_direction_turns_the_axis_so_the_part_moves_away_from_its_body() -> None:
    rng = np.random.default_rng(3)
    cloud, door = _oven_like_scene(rng, with_handle=True)
    plane = part_plane(cloud, door)
    assert plane is not None
    np.testing.assert_allclose(plane.outward, [-1.0, 0.0, 0.0], atol=1e-6)  # the body lies at x > 0
    # an oven-like door hinged along its bottom edge (the y axis through z = 0), handle at the top:
    # +y turns the top towards +x (into the body), so the opening axis is -y
    pivot, grasp = np.zeros(3), np.array([-0.03, 0.0, 0.35])
    for given in ([0.0, 1.0, 0.0], [0.0, -1.0, 0.0]):
        u = opening_direction("revolute", np.array(given), pivot, grasp, plane.outward)
        np.testing.assert_allclose(u, [0.0, -1.0, 0.0])
    # a drawer pulls out along the outward normal whichever sign was estimated
    u = opening_direction("prismatic", np.array([1.0, 0.0, 0.0]), pivot, grasp, plane.outward)
    np.testing.assert_allclose(u, [-1.0, 0.0, 0.0])


def _flat_part(rng: np.random.Generator, inside, n: int = 1500) -> np.ndarray:
    """Points of a flat part in the plane z = 0 where ``inside(x, y)``, over the square +-0.25 m."""
    xy = rng.uniform(-0.25, 0.25, size=(n, 2))
    xy = xy[inside(xy[:, 0], xy[:, 1])]
    return np.column_stack([xy, rng.normal(0.0, 0.002, len(xy))])


def test_edge_aligned_direction_snaps_onto_a_rectangles_edge_and_leaves_a_disc_alone() -> None:
    rng = np.random.default_rng(2)
    yaw = np.radians(7.0)
    c, s = np.cos(yaw), np.sin(yaw)
    # a 0.34 x 0.22 m lid turned 7 deg about z (its hinge edge along (-sin 7, cos 7, 0))
    lid = _flat_part(rng, lambda x, y: (np.abs(c * x + s * y) < 0.11) & (np.abs(-s * x + c * y) < 0.17))
    body = lid - np.array([0.0, 0.0, 0.03])  # the base under it, for the outward normal
    plane = part_plane(np.concatenate([lid, body]), lid)
    assert plane is not None
    true_axis = np.array([-s, c, 0.0])
    for err in (-25.0, 0.0, 12.0):  # CAPT's in-plane error, degrees
        e = np.radians(err)
        estimate = np.array([-np.sin(yaw + e), np.cos(yaw + e), 0.05])
        snapped = edge_aligned_direction(estimate, plane, lid)
        assert np.degrees(np.arccos(abs(snapped @ true_axis))) < 1.0, (err, snapped)
        assert snapped @ true_axis > 0  # the sign is the estimate's
    # 45 deg off lies between the edges: left alone
    off = np.array([-np.sin(yaw + 0.8), np.cos(yaw + 0.8), 0.0])
    np.testing.assert_allclose(edge_aligned_direction(off, plane, lid), off, atol=1e-9)
    # a round door has no edge to snap to
    disc = _flat_part(rng, lambda x, y: x**2 + y**2 < 0.2**2)
    plane = part_plane(np.concatenate([disc, disc - [0.0, 0.0, 0.03]]), disc)
    assert plane is not None
    estimate = unit(np.array([0.2, 1.0, 0.0]))
    np.testing.assert_allclose(edge_aligned_direction(estimate, plane, disc), estimate, atol=1e-9)


def test_hinge_on_edge_moves_a_far_off_line_onto_the_door_edge_away_from_the_handle() -> None:
    rng = np.random.default_rng(4)
    cloud, door = _oven_like_scene(rng, with_handle=True)
    plane = part_plane(cloud, door)
    assert plane is not None
    grasp = np.array([-0.03, 0.0, 0.35])  # handle at the top: the hinge is the bottom edge z = 0
    # CAPT's line: 12 deg out of the door's plane, 15 deg off in it, and 20 cm away from the edge
    tilt = np.array([np.sin(np.radians(12)), np.cos(np.radians(15)), np.sin(np.radians(15))])
    given = tilt / np.linalg.norm(tilt)
    u, pivot = hinge_on_edge(given, grasp, plane, door)
    assert abs(u @ plane.outward) < 1e-9  # in the door's plane
    assert u @ given > 0  # the sign is kept
    np.testing.assert_allclose(np.degrees(np.arccos(u @ [0.0, 1.0, 0.0])), 15.0, atol=0.5)
    # the line passes through the bottom edge where it crosses the door's middle (y ~ 0, z ~ 0)
    t = (np.array([0.0, 0.0, 0.0]) - pivot) @ u
    assert np.linalg.norm(pivot + t * u - [0.0, 0.0, 0.0]) < 0.02
    # a door hinged on its side (handle near y = +0.18): the line moves to the edge y = -0.2
    side_grasp = np.array([-0.03, 0.18, 0.2])
    u, pivot = hinge_on_edge(np.array([0.0, 0.0, -1.0]), side_grasp, plane, door)
    np.testing.assert_allclose(u, [0.0, 0.0, -1.0], atol=1e-9)
    np.testing.assert_allclose(pivot[:2], [0.0, -0.2], atol=0.02)
    np.testing.assert_allclose(pivot[2], side_grasp[2], atol=1e-9)  # the point closest to the grasp
    # an estimated pivot near that edge is kept (the hinge may sit behind the face or past the
    # visible edge), one 20 cm off is replaced by the edge
    near = np.array([0.03, -0.23, 0.1])
    u, pivot = hinge_on_edge(np.array([0.0, 0.0, -1.0]), side_grasp, plane, door, pivot=near)
    np.testing.assert_allclose(pivot, [0.03, -0.23, side_grasp[2]], atol=1e-9)
    u, pivot = hinge_on_edge(np.array([0.0, 0.0, -1.0]), side_grasp, plane, door,
                             pivot=np.array([0.1, -0.02, 0.1]))
    np.testing.assert_allclose(pivot[:2], [0.0, -0.2], atol=0.02)
    # an axis along the door's normal is no hinge of this door: the direction is left alone
    u, _ = hinge_on_edge(np.array([1.0, 0.0, 0.0]), grasp, plane, door)
    np.testing.assert_allclose(u, [1.0, 0.0, 0.0])
    # a bar (an eyeglasses temple, 40 x 1 cm) is not a panel: the line is left where it was
    bar = np.stack([np.zeros(200), rng.uniform(-0.2, 0.2, 200), rng.uniform(0.0, 0.01, 200)], axis=1)
    given_pivot = np.array([0.05, -0.1, 0.1])
    u, pivot = hinge_on_edge(np.array([0.0, 0.0, 1.0]), grasp, plane, bar, pivot=given_pivot)
    np.testing.assert_allclose(u, [0.0, 0.0, 1.0])
    np.testing.assert_allclose(pivot, [0.05, -0.1, 0.35], atol=1e-9)


def test_a_double_door_read_as_one_part_is_hinged_on_the_edge_on_its_handles_side() -> None:
    # Franka Kitchen's hinged cabinet: two 39 cm doors flush in the plane x = 0, meeting at y = 0,
    # their handles 8 cm either side of the seam. The network segments both as one 78 cm part;
    # the edge farthest from the right door's handle is the left door's hinge.
    rng = np.random.default_rng(6)
    doors = np.stack([np.zeros(1600), rng.uniform(-0.39, 0.39, 1600), rng.uniform(0.0, 0.4, 1600)], axis=1)
    body = np.stack([rng.uniform(0.02, 0.6, 800), rng.uniform(-0.39, 0.39, 800), np.full(800, 0.42)], axis=1)
    plane = part_plane(np.concatenate([doors, body]), doors)
    assert plane is not None
    right_handle, left_handle = np.array([-0.1, -0.08, 0.2]), np.array([-0.1, 0.08, 0.2])
    up, down = np.array([0.0, 0.0, 1.0]), np.array([0.0, 0.0, -1.0])
    _, pivot = hinge_on_edge(up, right_handle, plane, doors, other_handles=[left_handle])
    np.testing.assert_allclose(pivot[:2], [0.0, -0.39], atol=0.02)
    _, pivot = hinge_on_edge(down, left_handle, plane, doors, other_handles=[right_handle])
    np.testing.assert_allclose(pivot[:2], [0.0, 0.39], atol=0.02)
    # one handle, or the other one far above it (a knob on an oven's control strip): a single door,
    # hinged on the edge away from its handle
    for others in ([], [np.array([-0.05, 0.1, 0.38])]):
        _, pivot = hinge_on_edge(up, right_handle, plane, doors, other_handles=others)
        np.testing.assert_allclose(pivot[:2], [0.0, 0.39], atol=0.02)
    # off: the far edge, the other door's hinge
    _, pivot = hinge_on_edge(up, right_handle, plane, doors, other_handles=[left_handle], pair_doors=False)
    np.testing.assert_allclose(pivot[:2], [0.0, 0.39], atol=0.02)


def test_the_panel_of_a_half_segmented_door_gives_the_hinge_on_its_far_edge() -> None:
    rng = np.random.default_rng(5)
    cloud, door = _oven_like_scene(rng, with_handle=True)
    # a coplanar patch 10 cm beside the door (not joined to it) and points 2 cm behind its plane
    patch = np.stack([np.zeros(60), rng.uniform(0.3, 0.4, 60), rng.uniform(0.0, 0.4, 60)], axis=1)
    behind = np.stack([np.full(60, 0.02), rng.uniform(-0.2, 0.2, 60), rng.uniform(0.0, 0.4, 60)], axis=1)
    cloud = np.concatenate([cloud, patch, behind])
    # CAPT labelled only the handle's half of a door hinged at y = -0.2 (handle near y = +0.18)
    labelled = door[door[:, 1] > 0.05]
    plane = part_plane(cloud, labelled)
    assert plane is not None
    panel = coplanar_panel(cloud, labelled, plane)
    assert len(panel) == len(door)  # the whole door, neither the patch nor the points behind
    np.testing.assert_allclose(panel[:, 1].min(), door[:, 1].min())
    grasp = np.array([-0.03, 0.18, 0.2])
    _, pivot = hinge_on_edge(np.array([0.0, 0.0, -1.0]), grasp, plane, labelled)
    assert pivot[1] > 0.0  # on the labelled half's own edge: mid-door, 25 cm from the hinge
    _, pivot = hinge_on_edge(np.array([0.0, 0.0, -1.0]), grasp, plane, labelled, panel_points=panel)
    np.testing.assert_allclose(pivot[:2], [0.0, -0.2], atol=0.02)
    # a part with no other points in its plane is its own panel
    assert len(coplanar_panel(labelled, labelled, plane)) == len(labelled)


def test_a_handle_a_sparse_draw_loses_is_found_among_all_points() -> None:
    """A dense cloud (16x the model's input) with a small knob (64 points, 4 expected in a 1/16 draw,
    2 in this unlucky one): the draw alone has too few handle points; all points, with the minimum
    scaled 16x, find the knob."""
    from capt_env.wrappers.refiners.dense_handle_search import handle_search_points

    rng = np.random.default_rng(3)
    door = np.stack([np.zeros(8000), rng.uniform(-0.2, 0.2, 8000), rng.uniform(0.0, 0.4, 8000)], axis=1)
    body = np.stack([rng.uniform(0.02, 0.4, 8000), rng.uniform(-0.2, 0.2, 8000), np.full(8000, 0.45)],
                    axis=1)
    knob = np.stack([rng.uniform(-0.04, -0.03, 64), rng.uniform(0.14, 0.15, 64), rng.uniform(0.2, 0.21, 64)],
                    axis=1)
    dense = np.concatenate([door, body, knob])
    draw = np.concatenate([door[::16], body[::16], knob[:2]])
    geometry, min_points = handle_search_points(draw, None)
    assert geometry is draw and min_points == 3
    assert handle_point(geometry, door[::16], min_points=min_points) is None
    geometry, min_points = handle_search_points(draw, dense)
    assert len(geometry) == len(dense) and min_points == round(3 * len(dense) / len(draw))
    h = handle_point(geometry, door[::16], min_points=min_points)
    assert h is not None
    np.testing.assert_allclose(h, [-0.035, 0.145, 0.205], atol=0.01)
    # scattered stray points standing off the door are fewer than the scaled minimum: no handle
    stray = np.stack([np.full(20, -0.03), rng.uniform(-0.2, 0.2, 20), rng.uniform(0.0, 0.4, 20)], axis=1)
    assert handle_point(np.concatenate([door, body, stray]), door[::16], min_points=min_points) is None
