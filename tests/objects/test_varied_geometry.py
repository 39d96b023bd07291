"""Varied geometry (``capt_env.objects.style``): default instances unchanged, varied ones sound (base
parameters kept, handles hold the grasp point, shapes build, physics sane)."""

from __future__ import annotations

import hashlib
from collections import Counter

import numpy as np
import pytest

from capt_env.objects.geometry import quat_to_matrix
from capt_env.objects.physics_check import probe
from capt_env.objects.registry import CATEGORIES, make_object
from capt_env.objects.spec import Box, ConvexMesh, Cylinder
from capt_env.objects.style import GeometryVariation, draw_style

ALL = GeometryVariation(panels=True, handles=True, interiors=True)

# sha256[:16] of the specs of instances 0, 7, ..., 994 of every category, computed before varied
# geometry existed (the repr of each spec with the then-absent ``shapes=()`` and ``balanced=False``
# removed); sliding_panel's when the category was added, which came with its variation
DEFAULT_SPEC_HASHES = {
    "laptop": "d9ae6a9c67ee37d8",
    "oven": "3baa641e5d24cef5",
    "washing_machine": "cb9ae74dde9afb82",
    "eyeglasses": "48d48b6aee1edbe8",
    "drawer_cabinet": "418fb759177537b4",
    "cabinet_door": "3217e2ce16603e43",
    "sliding_panel": "544bc5fed5d4f5ba",
}


@pytest.mark.parametrize("category", CATEGORIES)
def test_default_instances_are_those_made_before_variation(category: str) -> None:
    h = hashlib.sha256()
    for i in range(0, 1000, 7):
        s = make_object(category, i)
        assert make_object(category, i, GeometryVariation()) == s
        key = (s.links, s.joints, s.target_joint, s.grasp_link, s.grasp_point, s.front)
        h.update(repr(key).replace(", shapes=()", "").replace(", balanced=False", "").encode())
    assert h.hexdigest()[:16] == DEFAULT_SPEC_HASHES[category]


def _inside(point: np.ndarray, shape: Box | Cylinder, tol: float = 1e-6) -> bool:
    local = (point - np.asarray(shape.pos)) @ quat_to_matrix(shape.quat)
    if isinstance(shape, Box):
        return bool(np.all(np.abs(local) <= np.asarray(shape.half_size) + tol))
    return abs(local[0]) <= shape.half_length + tol and np.hypot(local[1], local[2]) <= shape.radius + tol


@pytest.mark.parametrize("category", CATEGORIES)
def test_varied_instances_keep_base_parameters_and_hold_the_grasp_point(category: str) -> None:
    for i in range(0, 1000, 37):
        plain, varied = make_object(category, i), make_object(category, i, ALL)
        style = draw_style(category, i, ALL)
        assert varied.joints == plain.joints and varied.params == plain.params
        assert [link.name for link in varied.links] == [link.name for link in plain.links]
        lo, hi = varied.aabb()
        assert abs(lo[2]) < 1e-9 and float(np.max(hi - lo)) < 0.7
        link = varied.links[varied.link_index(varied.grasp_link)]
        grasp = np.asarray(varied.grasp_point)
        pieces = [*link.boxes, *(s for s in link.shapes if isinstance(s, Cylinder))]
        if category == "eyeglasses" or style.handle != "recessed":
            assert any(p.is_handle and _inside(grasp, p) for p in pieces), f"{category} #{i} {style}"
        elif category == "laptop":  # no lip: the lid's front edge
            assert not any(b.is_handle for b in link.boxes)
            assert abs(grasp[0] - plain.aabb()[0][0] - 0.0) < 0.04
        else:  # the pocket: in no piece, with its floor (a handle box) just behind
            assert not any(_inside(grasp, p) for p in pieces)
            floor = [b for b in link.boxes if b.is_handle]
            behind = np.array([floor[0].pos[0], grasp[1], grasp[2]])  # fronts face -x
            assert len(floor) == 1 and floor[0].pos[0] > grasp[0] and _inside(behind, floor[0], tol=0.0)


def test_each_option_varies_what_it_names() -> None:
    only = {name: GeometryVariation(**{name: True}) for name in ("panels", "handles", "interiors")}
    ids = range(0, 1000, 25)
    shapes = Counter(type(s).__name__ for i in ids for link in make_object("oven", i, only["panels"]).links
                     for s in link.shapes)
    assert shapes["ConvexMesh"] > 0 and shapes["Cylinder"] > 0  # shaped panels, cylindrical bars
    kinds = Counter(draw_style("drawer_cabinet", i, only["handles"]).handle for i in ids)
    assert set(kinds) == {"bar", "knob", "recessed", "lever"}
    assert all(draw_style("drawer_cabinet", i, only["handles"]).panel == "box" for i in ids)
    for category in ("oven", "washing_machine", "drawer_cabinet", "cabinet_door"):
        plain = make_object(category, 3)
        inner = make_object(category, 3, only["interiors"])
        assert len(inner.links[0].boxes) > len(plain.links[0].boxes), category
        assert inner.links[1:] == plain.links[1:] or category == "drawer_cabinet"


@pytest.mark.parametrize("category", CATEGORIES)
def test_varied_parts_neither_swing_nor_stick(category: str) -> None:
    for instance_id in range(0, 1000, 90):
        moved = probe(category, instance_id, seconds=1.0, start_fraction=0.3, variation=ALL)
        assert abs(moved["idle"]) < 0.05, (instance_id, moved)
        assert moved["pushed"] > 0.08, (instance_id, moved)


def test_varied_shapes_build_with_collision_shapes() -> None:
    import sapien.physx as px

    from capt_env.objects.builder import build_articulated_object
    from capt_env.objects.scene import create_scene

    scene = create_scene(render=False)
    for k, (category, iid) in enumerate((("washing_machine", 3), ("drawer_cabinet", 4), ("oven", 1))):
        spec = make_object(category, iid, ALL)
        art = build_articulated_object(scene, spec, name=f"varied_{k}")
        for link, built in zip(spec.links, art.links, strict=True):
            shapes = built._objs[0].get_collision_shapes()
            assert len(shapes) == len(link.boxes) + len(link.shapes)
            kinds = {type(s) for s in shapes}
            if any(isinstance(s, ConvexMesh) for s in link.shapes):
                assert px.PhysxCollisionShapeConvexMesh in kinds
            if any(isinstance(s, Cylinder) for s in link.shapes):
                assert px.PhysxCollisionShapeCylinder in kinds


def _lever_reach(category: str, instance_id: int) -> float:
    """Metres a varied lever's grasp point stands further off the front than the same instance's bar
    (fronts face -x; handles-only variation keeps the flat panel, so the face is the same)."""
    plain = make_object(category, instance_id)
    lever = make_object(category, instance_id, GeometryVariation(handles=True))
    return float(plain.grasp_point[0] - lever.grasp_point[0])


def test_side_door_levers_stand_off_as_far_as_door_levers_do_and_others_stay_short() -> None:
    from capt_env.objects.style import LEVER_MAX_STANDOFF

    only_handles = GeometryVariation(handles=True)
    for category, long_levers in (("cabinet_door", True), ("washing_machine", True), ("oven", False),
                                  ("drawer_cabinet", False)):
        ids = [i for i in range(0, 1000, 7) if draw_style(category, i, only_handles).handle == "lever"
               and make_object(category, i).params.get("handle_style", "bar") == "bar"][:12]
        reach = np.array([_lever_reach(category, i) for i in ids])
        assert len(ids) >= 8, category
        if long_levers:  # stems spread from the category's 3-4.5 cm up to 13 cm
            assert reach.min() > -1e-6 and reach.max() < LEVER_MAX_STANDOFF - 0.03 + 1e-6, (category, reach)
            assert reach.max() - reach.min() > 0.04, (category, reach)
        else:
            np.testing.assert_allclose(reach, 0.0, atol=1e-6, err_msg=category)


def test_openings_lower_a_drawer_front_below_its_opening_and_keep_the_joint() -> None:
    openings = GeometryVariation(openings=True)
    fills = []
    for i in range(0, 1000, 41):
        plain, varied = make_object("drawer_cabinet", i), make_object("drawer_cabinet", i, openings)
        style = draw_style("drawer_cabinet", i, openings)
        fills.append(style.front_fill)
        assert varied.joints == plain.joints and varied.params == plain.params
        assert plain.links[0] == varied.links[0]  # the carcass and its openings as they were
        for a, b in zip(plain.links[1:], varied.links[1:], strict=True):
            top_plain = max(bx.pos[2] + bx.half_size[2] for bx in a.boxes)
            top_varied = max(bx.pos[2] + bx.half_size[2] for bx in b.boxes)
            low_plain = min(bx.pos[2] - bx.half_size[2] for bx in a.boxes)
            assert top_varied < top_plain - 0.005  # a gap above the front, into the carcass
            height = top_plain - low_plain
            assert 0.55 * height < top_varied - low_plain < 0.95 * height
        link = varied.links[varied.link_index(varied.grasp_link)]
        assert any(bx.is_handle and _inside(np.asarray(varied.grasp_point), bx) for bx in link.boxes)
    assert 0.6 <= min(fills) and max(fills) <= 0.9 and max(fills) - min(fills) > 0.15
    assert make_object("oven", 3, openings) == make_object("oven", 3)  # other categories ignore it


def _extent(spec, axis: int) -> float:
    lows = [bx.pos[axis] - bx.half_size[axis] for bx in spec.links[0].boxes]
    highs = [bx.pos[axis] + bx.half_size[axis] for bx in spec.links[0].boxes]
    return max(highs) - min(lows)


def test_proportions_draw_narrow_shallow_drawer_cabinets_and_tall_drawer_boxes() -> None:
    sizes = GeometryVariation(proportions=True)
    widths, depths, box_fracs = [], [], []
    for i in range(0, 1000, 37):
        plain, varied = make_object("drawer_cabinet", i), make_object("drawer_cabinet", i, sizes)
        width, depth = _extent(varied, 1), _extent(varied, 0)
        assert varied.params["width"] == pytest.approx(width)
        assert varied.params["depth"] == pytest.approx(depth)
        widths.append(width)
        depths.append(depth)
        box_fracs.append(varied.params["drawer_box_height_frac"])
        shared = set(plain.params) - {"width", "depth", "drawer_box_height_frac"}
        assert {k: varied.params[k] for k in shared} == {k: plain.params[k] for k in shared}
        assert _extent(varied, 2) == pytest.approx(_extent(plain, 2))  # the height is the drawers'
        for joint, plain_joint in zip(varied.joints, plain.joints, strict=True):
            # the travel is the same share of the (new) drawer depth
            ratio = plain_joint.limits[1] / (plain.params["depth"] - plain.params["wall"]
                                             - plain.params["front_thickness"])
            assert joint.limits[1] == pytest.approx(
                ratio * (depth - varied.params["wall"] - varied.params["front_thickness"]))
            assert joint.limits[1] < depth
        for link in varied.links[1:]:  # every drawer inside its carcass's width, its box as drawn
            assert max(abs(bx.pos[1]) + bx.half_size[1] for bx in link.boxes) < width / 2
            front, walls = link.boxes[0], [bx for bx in link.boxes[1:] if not bx.is_handle][:3]
            low = front.pos[2] - front.half_size[2]
            box_top = max(bx.pos[2] + bx.half_size[2] for bx in walls)
            assert box_top - low == pytest.approx(
                varied.params["drawer_box_height_frac"] * 2 * front.half_size[2], abs=1e-9)
        link = varied.links[varied.link_index(varied.grasp_link)]
        assert any(bx.is_handle and _inside(np.asarray(varied.grasp_point), bx) for bx in link.boxes)
    assert min(widths) < 0.22 and max(widths) > 0.40 and min(depths) < 0.20 and max(depths) > 0.38
    assert sum(w < 0.30 for w in widths) >= 5 and sum(d < 0.28 for d in depths) >= 5
    assert min(box_fracs) >= 0.6 and max(box_fracs) > 0.9 and sum(f > 0.8 for f in box_fracs) >= 5
    assert make_object("oven", 3, sizes) == make_object("oven", 3)  # other categories ignore it


def test_proportions_draw_cabinet_doors_beyond_the_category_and_the_door_follows() -> None:
    sizes = GeometryVariation(proportions=True)
    extents = []
    for i in range(0, 1000, 37):
        plain, varied = make_object("cabinet_door", i), make_object("cabinet_door", i, sizes)
        size = np.array([_extent(varied, 1), _extent(varied, 0), _extent(varied, 2)])  # width, depth, height
        np.testing.assert_allclose(size, [varied.params[k] for k in ("width", "depth", "height")])
        extents.append(size)
        shared = set(plain.params) - {"width", "depth", "height"}
        assert {k: varied.params[k] for k in shared} == {k: plain.params[k] for k in shared}
        door = varied.links[varied.link_index("door")].boxes[0]  # the panel: the carcass's front
        assert 2 * door.half_size[1] == pytest.approx(size[0] - 0.004)
        assert 2 * door.half_size[2] == pytest.approx(size[2] - 0.004)
        assert varied.joints[0].limits == plain.joints[0].limits
        assert varied.joints[0].origin[0] == pytest.approx(-size[1] / 2)  # the hinge on the front
    low, high = np.min(extents, axis=0), np.max(extents, axis=0)
    assert np.all(low < [0.26, 0.22, 0.30]) and np.all(high > [0.55, 0.45, 0.70])
