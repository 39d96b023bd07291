"""MJCF to URDF: fragments with includes and default classes, frames, joints, groups, errors."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest
import trimesh
from lxml import etree

from capt_env.objects.errors import ObjectFileError
from capt_env.objects.mjcf_to_urdf import convert_mjcf, dependencies_file

DEPENDENCIES = """<mujocoinclude>
  <compiler angle="radian"/>
  <asset><mesh name="lid_mesh" file="meshes/lid.stl" scale="1 1 2"/>
         <material name="green" rgba="0 1 0 1"/></asset>
  <default>
    <default class="box_base">
      <joint damping="0.5" frictionloss="0.2"/>
      <geom contype="0" conaffinity="0" group="1" type="mesh"/>
      <default class="box_col"><geom contype="1" conaffinity="1" group="4" type="box"/></default>
    </default>
  </default>
</mujocoinclude>
"""

FRAGMENT = """<mujocoinclude>
  <include file="parts/base_geoms.xml"/>
  <body childclass="box_base" pos="0.1 0 0">
    <body name="lid" pos="0 0.2 0.1">
      <joint type="hinge" axis="1 0 0" range="0 1.5" pos="0 -0.05 0"/>
      <geom mesh="lid_mesh" material="green" name="lid_visual"/>
      <geom class="box_col" size="0.1 0.05 0.005" mass="0.2"/>
      <geom class="box_col" type="capsule" fromto="-0.05 0.04 0.01 0.05 0.04 0.01" size="0.008" name="grip"/>
    </body>
  </body>
</mujocoinclude>
"""

BASE_GEOMS = """<mujocoinclude><geom type="box" size="0.2 0.2 0.02" pos="0 0 0.02" group="1"/></mujocoinclude>
"""


@pytest.fixture()
def fragment(tmp_path: Path) -> Path:
    (tmp_path / "meshes").mkdir()
    trimesh.creation.box(extents=[0.2, 0.1, 0.005]).export(tmp_path / "meshes" / "lid.stl")
    (tmp_path / "parts").mkdir()
    (tmp_path / "parts" / "base_geoms.xml").write_text(BASE_GEOMS)
    (tmp_path / "box_dependencies.xml").write_text(DEPENDENCIES)
    path = tmp_path / "box_lid.xml"
    path.write_text(FRAGMENT)
    return path


def _urdf(conv) -> etree._Element:
    return etree.parse(str(conv.urdf_path)).getroot()


def test_fragment_with_include_default_class_and_mesh_converts(fragment: Path, tmp_path: Path) -> None:
    assert dependencies_file(fragment).name == "box_dependencies.xml"
    conv = convert_mjcf(fragment, tmp_path / "out")
    root = _urdf(conv)
    assert conv.angle == "radian" and conv.joint_names == ["lid_joint0"]
    joint = root.find("joint[@name='lid_joint0']")
    assert joint.get("type") == "revolute"
    assert joint.find("limit").get("upper") == "1.5"  # radians from the dependencies' compiler
    # the URDF child frame sits at the joint's position: body pos + joint pos (parent body at x = 0.1)
    assert np.allclose([float(v) for v in joint.find("origin").get("xyz").split()], [0.0, 0.15, 0.1])
    dyn = joint.find("dynamics")
    assert float(dyn.get("damping")) == 0.5 and float(dyn.get("friction")) == 0.2  # childclass defaults
    lid = root.find("link[@name='lid']")
    visuals = {v.get("name"): v for v in lid.findall("visual")}
    assert set(visuals) == {"lid_visual"}  # group 1 is drawn, group 4 only collides
    mesh = visuals["lid_visual"].find("geometry/mesh")
    assert mesh.get("filename") == str((fragment.parent / "meshes" / "lid.stl").resolve())
    assert mesh.get("scale") == "1 1 2"
    # geoms are shifted by -joint pos into the joint-centred link frame
    xyz = [float(v) for v in visuals["lid_visual"].find("origin").get("xyz").split()]
    assert np.allclose(xyz, [0, 0.05, 0])
    collisions = {c.get("name"): c for c in lid.findall("collision")}
    capsule = collisions["grip"].find("geometry/capsule")
    assert float(capsule.get("length")) == pytest.approx(0.1) and float(capsule.get("radius")) == 0.008
    grip_rpy = [float(v) for v in collisions["grip"].find("origin").get("rpy").split()]
    assert abs(abs(grip_rpy[1]) - np.pi / 2) < 1e-6  # along x
    # the included base geom lands on the base link; the unnamed body becomes a named link
    assert root.find("link[@name='base']/visual") is not None
    assert root.find("link[@name='body0']") is not None
    mass = float(lid.find("inertial/mass").get("value"))
    assert mass > 0.2  # the box's 0.2 kg plus the capsule at density 1000


def test_a_chain_fragment_reads_the_classes_and_meshes_of_its_sibling_asset_file(tmp_path: Path) -> None:
    # Franka Kitchen (adept_models): microwave_chain.xml holds the bodies, microwave_asset.xml
    # the classes and meshes; a sibling of another object and a body file are not read
    (tmp_path / "meshes").mkdir()
    trimesh.creation.box(extents=[0.2, 0.1, 0.005]).export(tmp_path / "meshes" / "lid.stl")
    (tmp_path / "box_asset.xml").write_text(DEPENDENCIES)
    (tmp_path / "b_asset.xml").write_text("<mujocoinclude/>")  # a shorter prefix of the stem
    (tmp_path / "boxes_chain2.xml").write_text("<mujocoinclude/>")
    chain = tmp_path / "box_chain.xml"
    chain.write_text('<mujocoinclude><body childclass="box_base"><geom type="box" size="0.1 0.1 0.1"/>'
                     '<body name="lid" pos="0 0 0.1"><joint type="hinge" axis="1 0 0" range="0 1.5"/>'
                     '<geom mesh="lid_mesh"/></body></body></mujocoinclude>')
    assert dependencies_file(chain).name == "box_asset.xml"
    conv = convert_mjcf(chain, tmp_path / "out")
    joint = _urdf(conv).find("joint[@type='revolute']")
    assert float(joint.find("dynamics").get("damping")) == 0.5  # the asset file's class
    assert joint.find("limit").get("upper") == "1.5"  # its compiler's radians
    assert dependencies_file(tmp_path / "other_chain.xml") is None


def test_fragment_without_compiler_reads_radian_ranges_and_says_so(tmp_path: Path) -> None:
    path = tmp_path / "flap.xml"
    path.write_text('<mujocoinclude><body name="flap"><joint type="hinge" range="0 0.4"/>'
                    '<geom type="box" size="0.1 0.1 0.01"/></body></mujocoinclude>')
    conv = convert_mjcf(path, tmp_path / "out")
    assert conv.angle == "radian" and any("radian" in w for w in conv.warnings)
    assert _urdf(conv).find("joint[@type='revolute']/limit").get("upper") == "0.4"
    full = tmp_path / "full.xml"
    full.write_text('<mujoco><worldbody><body name="flap"><joint type="hinge" range="0 90"/>'
                    '<geom type="box" size="0.1 0.1 0.01"/></body></worldbody></mujoco>')
    limit = _urdf(convert_mjcf(full, tmp_path / "out2")).find("joint[@type='revolute']/limit")
    assert float(limit.get("upper")) == pytest.approx(np.pi / 2)  # a full model's default is degrees


def test_a_full_model_whose_hinge_would_turn_under_a_degree_reads_its_range_in_radians(
        tmp_path: Path) -> None:
    # robosuite's door: a full model with no compiler angle, merged into a radian scene by its
    # framework; in degrees its 0-0.4 range would turn the door 0.4 deg
    full = tmp_path / "door.xml"
    full.write_text('<mujoco><worldbody><body name="door"><joint type="hinge" range="0.0 0.4"/>'
                    '<geom type="box" size="0.2 0.02 0.3"/></body></worldbody></mujoco>')
    conv = convert_mjcf(full, tmp_path / "out")
    assert conv.angle == "radian" and any("would open nothing" in w for w in conv.warnings)
    assert _urdf(conv).find("joint[@type='revolute']/limit").get("upper") == "0.4"
    # the override still wins
    forced = convert_mjcf(full, tmp_path / "out2", angle="degree")
    upper = float(_urdf(forced).find("joint[@type='revolute']/limit").get("upper"))
    assert upper == pytest.approx(np.radians(0.4))


def test_bad_include_malformed_file_and_missing_mesh_name_the_file_and_element(fragment: Path,
                                                                               tmp_path: Path) -> None:
    bad = tmp_path / "bad_include.xml"
    bad.write_text('<mujoco><include file="nowhere.xml"/><worldbody/></mujoco>')
    with pytest.raises(ObjectFileError, match=r"bad_include\.xml: <include file='nowhere.xml'> not found"):
        convert_mjcf(bad, tmp_path / "o1")
    broken = tmp_path / "broken.xml"
    broken.write_text("<mujoco><worldbody><body></worldbody></mujoco>")
    with pytest.raises(ObjectFileError, match=r"broken\.xml: malformed XML at line 1"):
        convert_mjcf(broken, tmp_path / "o2")
    (fragment.parent / "meshes" / "lid.stl").unlink()
    missing = r"box_dependencies\.xml: mesh 'lid_mesh': file 'meshes/lid\.stl' not found"
    with pytest.raises(ObjectFileError, match=missing):
        convert_mjcf(fragment, tmp_path / "o3")


def test_converted_fragment_loads_and_hinges_about_its_joint(fragment: Path) -> None:
    from capt_env.objects.builder import joint_world_axis
    from capt_env.objects.scene import create_scene
    from capt_env.objects.user_files import load_user_object

    art, info = load_user_object(create_scene(render=False), fragment, name="lidbox")
    assert info["format"] == "mjcf" and info["joint"] == "lid_joint0"
    direction, pivot = joint_world_axis(art, "lid_joint0")
    assert np.allclose(direction, [1, 0, 0], atol=1e-6) and np.allclose(pivot[1:], [0.15, 0.1], atol=1e-6)
    assert float(info and art.joints_map["lid_joint0"].limits.reshape(-1)[1]) == pytest.approx(1.5)
