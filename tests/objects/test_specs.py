"""Procedural object specs: determinism, variety, the sign rule, handles and grasp points, errors."""

from __future__ import annotations

import numpy as np
import pytest

from capt_env.objects.geometry import box_corners, quat_from_x_to, quat_to_matrix, rotate_about_axis
from capt_env.objects.registry import CATEGORIES, PAPER_CATEGORIES, make_object
from capt_env.objects.sampling import NUM_INSTANCES

GRIPPER_OPENING = 0.08  # m, Panda


@pytest.mark.parametrize("category", CATEGORIES)
def test_same_id_gives_equal_spec(category: str) -> None:
    a, b = make_object(category, 17), make_object(category, 17)
    assert a == b
    assert a.params == b.params


def test_the_package_exports_the_entry_points_the_readme_names() -> None:
    import capt_env.objects as objects
    from capt_env.objects.splits import instance_ids

    assert objects.make_object("oven", 17) == make_object("oven", 17)
    assert objects.instance_ids("oven", "test") == instance_ids("oven", "test")
    assert objects.CATEGORIES == CATEGORIES


@pytest.mark.parametrize("category", CATEGORIES)
def test_hundred_ids_give_hundred_distinct_parameter_sets(category: str) -> None:
    keys = set()
    for i in range(100):
        spec = make_object(category, i)
        keys.add(tuple(sorted((k, repr(v)) for k, v in spec.params.items())))
    assert len(keys) == 100
    assert make_object(category, 0) != make_object(category, 1)


@pytest.mark.parametrize("category", CATEGORIES)
def test_structure_sign_rule_and_sizes(category: str) -> None:
    for i in range(0, NUM_INSTANCES, 97):
        spec = make_object(category, i)
        names = [link.name for link in spec.links]
        assert len(set(names)) == len(names)
        assert len({j.name for j in spec.joints}) == len(spec.joints) >= 1
        for joint in spec.joints:
            lo, hi = joint.limits
            assert lo <= 0.0 <= hi and hi > lo  # state 0 (closed) is within limits
            assert abs(np.linalg.norm(joint.axis) - 1.0) < 1e-9
            assert names.index(joint.parent) < names.index(joint.child)
            assert joint.damping > 0 and joint.friction >= 0
        spec.joint_index(spec.target_joint)
        lo, hi = spec.aabb()
        assert abs(lo[2]) < 1e-9  # rests on z = 0
        assert 0.1 < float(np.max(hi - lo)) < 0.65  # Panda-sized
        assert sum(len(link.boxes) for link in spec.links) <= 30


def _inside(point: np.ndarray, box) -> bool:
    local = (point - np.asarray(box.pos)) @ quat_to_matrix(box.quat)
    return bool(np.all(np.abs(local) <= np.asarray(box.half_size) + 1e-9))


@pytest.mark.parametrize("category", CATEGORIES)
def test_target_link_has_graspable_handle_at_grasp_point(category: str) -> None:
    for i in range(0, NUM_INSTANCES, 83):
        spec = make_object(category, i)
        target = spec.joints[spec.joint_index(spec.target_joint)]
        assert spec.grasp_link == target.child
        link = spec.links[spec.link_index(spec.grasp_link)]
        handles = [b for b in link.boxes if b.is_handle]
        assert handles, f"{category} #{i}: no handle on {link.name}"
        grasp = np.asarray(spec.grasp_point)
        holding = [b for b in handles if _inside(grasp, b)]
        assert holding, f"{category} #{i}: grasp point not in a handle box"
        # thin enough for the gripper in at least one direction across the handle
        assert min(2 * np.asarray(holding[0].half_size)) < GRIPPER_OPENING / 2


@pytest.mark.parametrize("category", ["oven", "cabinet_door", "washing_machine", "drawer_cabinet"])
def test_handles_stand_off_the_front(category: str) -> None:
    for i in range(0, NUM_INSTANCES, 101):
        spec = make_object(category, i)
        link = spec.links[spec.link_index(spec.grasp_link)]
        front_x = min(box_corners(b)[:, 0].min() for b in link.boxes if not b.is_handle)
        assert 0.025 <= front_x - spec.grasp_point[0] <= 0.07  # grasp centre 2.5-7 cm in front of it


@pytest.mark.parametrize("category", CATEGORIES)
def test_opening_moves_grasp_point_towards_front_or_up(category: str) -> None:
    """The sign rule seen from outside: +state moves the grasp point out of the closed body."""
    spec = make_object(category, 5)
    joint = spec.joints[spec.joint_index(spec.target_joint)]
    grasp = np.asarray(spec.grasp_point)[None]
    step = 0.3
    if joint.type == "revolute":
        moved = rotate_about_axis(grasp, joint.axis, joint.origin, step)[0]
    else:
        moved = grasp[0] + step * np.asarray(joint.axis)
    delta = moved - grasp[0]
    if category == "laptop":
        assert delta[2] > 0.02
    elif category == "eyeglasses":
        assert delta[0] > 0.01  # temples unfold backwards (+x)
    elif category == "sliding_panel":
        assert abs(delta[0]) < 1e-9 and np.linalg.norm(delta[1:]) > 0.2  # across the front plane
    else:
        assert delta[0] < -0.02  # towards the robot (-x)


def test_quat_from_x_to_maps_x_onto_direction() -> None:
    for d in ([0, 0, 1], [0, -1, 0], [-1, 0, 0], [1, 0, 0], [0.3, -0.4, 0.866]):
        d = np.asarray(d, dtype=float) / np.linalg.norm(d)
        assert np.allclose(quat_to_matrix(quat_from_x_to(d))[:, 0], d, atol=1e-12)


def test_paper_categories_are_known() -> None:
    assert set(PAPER_CATEGORIES) == {"laptop", "oven", "washing_machine", "eyeglasses"}


def test_unknown_category_error_names_known_ones() -> None:
    with pytest.raises(ValueError, match="laptop"):
        make_object("toaster", 0)


@pytest.mark.parametrize("bad", [-1, NUM_INSTANCES, 10**9, 1.5, True])
def test_bad_instance_id(bad) -> None:
    with pytest.raises(ValueError, match="instance_id"):
        make_object("laptop", bad)


@pytest.mark.parametrize("category", ["oven", "washing_machine", "cabinet_door"])
def test_hinged_door_objects_target_their_door(category: str) -> None:
    spec = make_object(category, 5)
    assert [link.name for link in spec.links] == ["body", "door"]
    assert spec.links[0].density == 400.0
    assert (spec.target_joint, spec.grasp_link) == ("door_hinge", "door")


def test_hinged_door_object_refuses_a_hinge_on_another_link() -> None:
    from capt_env.objects.spec import Box, JointSpec, LinkSpec, hinged_door_object

    door = LinkSpec("door", (Box((0.1, 0.1, 0.01)),))
    hinge = JointSpec("door_hinge", "revolute", "body", "lid", (0.0, 0.0, 0.0), (0.0, 0.0, 1.0), (0.0, 1.5))
    with pytest.raises(ValueError, match="'body' to 'door', got 'body' -> 'lid'"):
        hinged_door_object("oven", 0, [Box((0.2, 0.2, 0.2))], door, hinge, (0.0, 0.0, 0.0), {})
