"""User URDF/MJCF objects: end-to-end URDF round trip of procedural specs, MJCF loading, errors."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

from capt_env.objects.builder import joint_world_axis
from capt_env.objects.registry import CATEGORIES, make_object
from capt_env.objects.scene import create_scene
from capt_env.objects.user_files import (
    FRICTION_MAX_SPEED,
    FRICTION_SATURATION_SPEED,
    load_user_object,
    spec_to_urdf,
)

MJCF = """<mujoco model="box_door">
  <worldbody>
    <body name="frame" pos="0 0 0">
      <geom type="box" size="0.2 0.2 0.02" pos="0 0 0.02"/>
      <body name="flap" pos="0.2 0 0.05">
        <joint name="flap_hinge" type="hinge" axis="0 1 0" range="0 90" damping="1"/>
        <geom type="box" size="0.15 0.15 0.01" pos="-0.15 0 0"/>
      </body>
      <body name="slider" pos="0 0 0.2">
        <joint name="slide" type="slide" axis="1 0 0" range="0 0.2"/>
        <geom type="box" size="0.05 0.05 0.05"/>
      </body>
    </body>
  </worldbody>
</mujoco>
"""


@pytest.fixture(scope="module")
def scene():
    return create_scene(render=False)


@pytest.mark.parametrize("category", CATEGORIES)
def test_urdf_round_trip(scene, tmp_path: Path, category: str) -> None:
    spec = make_object(category, 7)
    path = tmp_path / f"{category}.urdf"
    path.write_text(spec_to_urdf(spec))
    art, info = load_user_object(scene, path, name=f"urdf_{category}")
    assert info["format"] == "urdf"
    assert info["joint"] == spec.joints[0].name
    assert info["movable_joints"] == [j.name for j in spec.joints]
    assert sorted(link.name for link in art.links) == sorted(link.name for link in spec.links)
    for joint in spec.joints:
        direction, pivot = joint_world_axis(art, joint.name)
        assert np.allclose(direction, joint.axis, atol=1e-4)
        # the pivot lies on the spec's axis line
        off = pivot - np.asarray(joint.origin)
        assert np.linalg.norm(off - (off @ direction) * direction) < 1e-4
        sim_joint = art.joints_map[joint.name]
        assert sim_joint.limits.reshape(-1).tolist() == pytest.approx(joint.limits, abs=1e-5)
        # URDF friction is a Coulomb force/torque: a velocity drive capped at friction + damping * 1
        assert float(sim_joint.force_limit[0]) == pytest.approx(
            joint.friction + joint.damping * FRICTION_MAX_SPEED, rel=1e-5)
        assert float(sim_joint.damping[0]) == pytest.approx(
            max(joint.damping, joint.friction / FRICTION_SATURATION_SPEED), rel=1e-5)
    # masses from the URDF inertials match the spec's box volumes x density
    link = spec.links[-1]
    volume = sum(float(np.prod(2 * np.asarray(b.half_size))) for b in link.boxes)
    assert float(art.links_map[link.name].mass[0]) == pytest.approx(volume * link.density, rel=1e-3)


def test_urdf_joint_by_name_and_scale(scene, tmp_path: Path) -> None:
    spec = make_object("eyeglasses", 3)
    path = tmp_path / "glasses.urdf"
    path.write_text(spec_to_urdf(spec))
    art, info = load_user_object(scene, path, joint="temple_right_hinge", scale=2.0, name="glasses2")
    assert info["joint"] == "temple_right_hinge"
    _, pivot = joint_world_axis(art, "temple_right_hinge")
    origin = 2.0 * np.asarray(spec.joints[1].origin)
    assert np.allclose(pivot[:2], origin[:2], atol=1e-4)


def test_mjcf(scene, tmp_path: Path) -> None:
    path = tmp_path / "door.xml"
    path.write_text(MJCF)
    art, info = load_user_object(scene, path, name="mjcf_door")
    assert info["format"] == "mjcf"
    assert set(info["movable_joints"]) == {"flap_hinge", "slide"}
    assert info["joint"] == info["movable_joints"][0]
    _, info2 = load_user_object(scene, path, joint="slide", name="mjcf_door2")
    assert info2["joint"] == "slide" and info2["joint_type"] == "prismatic"
    direction, _ = joint_world_axis(art, "flap_hinge")
    assert np.allclose(np.abs(direction), [0, 1, 0], atol=1e-4)


def test_errors(scene, tmp_path: Path) -> None:
    missing = tmp_path / "nope.urdf"
    with pytest.raises(FileNotFoundError, match="nope.urdf"):
        load_user_object(scene, missing)
    odd = tmp_path / "object.obj"
    odd.write_text("v 0 0 0\n")
    with pytest.raises(ValueError, match="suffix"):
        load_user_object(scene, odd)
    path = tmp_path / "laptop.urdf"
    path.write_text(spec_to_urdf(make_object("laptop", 1)))
    with pytest.raises(ValueError, match="lid_hinge"):  # lists the movable joints
        load_user_object(scene, path, joint="door_hinge", name="err1")
    rigid = tmp_path / "rigid.urdf"
    rigid.write_text(
        '<?xml version="1.0"?><robot name="r"><link name="a"><collision><geometry><box size="0.1 0.1 0.1"/>'
        '</geometry></collision></link><link name="b"><collision><geometry><box size="0.1 0.1 0.1"/>'
        '</geometry></collision></link><joint name="weld" type="fixed"><parent link="a"/><child link="b"/>'
        '<origin xyz="0 0 0.2"/></joint></robot>'
    )
    with pytest.raises(ValueError, match="no movable"):
        load_user_object(scene, rigid, name="err2")
