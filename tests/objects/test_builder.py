"""Building specs in a ManiSkill scene: the simulator's joint axes, names and counts match the spec."""

from __future__ import annotations

import numpy as np
import pytest
import sapien

from capt_env.objects.builder import build_articulated_object, joint_world_axis, link_segmentation_ids
from capt_env.objects.geometry import quat_from_axis_angle, quat_to_matrix
from capt_env.objects.registry import CATEGORIES, make_object
from capt_env.objects.scene import create_scene

ROOT_Q = quat_from_axis_angle((0.2, -0.3, 1.0), 0.7)
ROOT_P = np.array([0.4, -0.2, 0.1])


@pytest.fixture(scope="module")
def scene():
    return create_scene(render=False)


@pytest.mark.parametrize("category", CATEGORIES)
def test_built_axes_names_and_counts_match_spec(scene, category: str) -> None:
    spec = make_object(category, 11)
    art = build_articulated_object(scene, spec, name=f"obj_{category}", pose=sapien.Pose(ROOT_P, ROOT_Q))
    assert [link.name for link in art.links] == [link.name for link in spec.links]
    assert [j.name for j in art.active_joints] == [j.name for j in spec.joints]
    assert art.dof[0] == len(spec.joints)
    assert np.allclose(art.qpos.numpy(), 0.0)
    rot = quat_to_matrix(ROOT_Q)
    for joint in spec.joints:
        direction, pivot = joint_world_axis(art, joint.name)
        expected_dir = rot @ np.asarray(joint.axis)
        assert np.allclose(direction, expected_dir, atol=1e-4)
        # the simulator's pivot lies on the spec's axis line (here: it is the spec's origin)
        assert np.allclose(pivot, rot @ np.asarray(joint.origin) + ROOT_P, atol=1e-4)
        sim_joint = art.joints_map[joint.name]
        assert float(sim_joint.friction[0]) == pytest.approx(joint.friction, rel=1e-5)
        assert float(sim_joint.damping[0]) == pytest.approx(joint.damping, rel=1e-5)
        lo, hi = sim_joint.limits.reshape(-1).tolist()
        assert (lo, hi) == pytest.approx(joint.limits, abs=1e-5)
    ids = link_segmentation_ids(art)
    assert list(ids) == [link.name for link in spec.links]
    assert len(set(ids.values())) == len(spec.links)


def test_scale_scales_geometry_and_prismatic_limits(scene) -> None:
    spec = make_object("drawer_cabinet", 4)
    art = build_articulated_object(scene, spec, name="scaled_drawers", scale=1.5)
    joint = spec.joints[0]
    _, pivot = joint_world_axis(art, joint.name)
    assert np.allclose(pivot, 1.5 * np.asarray(joint.origin), atol=1e-5)
    lo, hi = art.joints_map[joint.name].limits.reshape(-1).tolist()
    assert hi == pytest.approx(1.5 * joint.limits[1], rel=1e-5)


def test_bad_scale_rejected(scene) -> None:
    with pytest.raises(ValueError, match="scale"):
        build_articulated_object(scene, make_object("laptop", 0), name="bad", scale=0.0)


@pytest.mark.render
def test_build_with_visuals_and_colours() -> None:
    render_scene = create_scene(render=True)
    spec = make_object("oven", 2)
    art = build_articulated_object(render_scene, spec, name="oven_vis")
    body = art.links[0]._objs[0].entity
    from sapien.render import RenderBodyComponent

    visual = body.find_component_by_type(RenderBodyComponent)
    assert visual is not None and len(visual.render_shapes) == len(spec.links[0].boxes)
    colour = visual.render_shapes[0].material.base_color
    assert np.allclose(colour, spec.links[0].boxes[0].color, atol=1e-6)
