"""User files in the task: loading edge cases, clear errors, the closed limit, the front direction."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest
import trimesh

from capt_env.objects.errors import ObjectFileError
from capt_env.objects.user_files import prepare_object_file
from capt_env.tasks.open_articulated import OpenArticulatedEnv

STILL = {"yaw_noise": 0.0, "object_xy_noise": [0.0, 0.0]}


def cabinet_urdf(front: str = "-x", lower: float = 0.0, upper: float = 1.5, axis_sign: float = 1.0,
                 extra_link: bool = False, mesh: str | None = None) -> str:
    """A 30 x 40 x 50 cm cabinet body and a door hinged on its front's left edge.

    ``front`` is the side the door is on (``-x`` or ``+y``); the hinge axis is vertical with sign
    ``axis_sign``; the door's handle is a box named ``pull_bar``."""
    if front == "-x":
        door_origin, panel, handle = "-0.16 -0.2 0.25", "0 0.2 0", "-0.03 0.35 0"
        panel_size = "0.02 0.4 0.5"
    else:  # door on +y, hinge at its right (-x) edge seen from +y
        door_origin, panel, handle = "-0.15 0.21 0.25", "0.15 0 0", "0.27 0.03 0"
        panel_size = "0.3 0.02 0.5"
    body = f'<mesh filename="{mesh}"/>' if mesh else '<box size="0.3 0.4 0.5"/>'
    empty = ('<link name="latch_frame"/><joint name="latch_fix" type="fixed"><parent link="door"/>'
             '<child link="latch_frame"/></joint>') if extra_link else ""
    return f"""<?xml version="1.0"?>
<robot name="cab">
  <link name="body"><visual><origin xyz="0 0 0.25"/><geometry>{body}</geometry></visual>
    <collision><origin xyz="0 0 0.25"/><geometry><box size="0.3 0.4 0.5"/></geometry></collision></link>
  <link name="door">
    <inertial><mass value="0.5"/>
      <inertia ixx="0.01" iyy="0.01" izz="0.01" ixy="0" ixz="0" iyz="0"/></inertial>
    <visual><origin xyz="{panel}"/><geometry><box size="{panel_size}"/></geometry></visual>
    <collision><origin xyz="{panel}"/><geometry><box size="{panel_size}"/></geometry></collision>
    <visual name="pull_bar"><origin xyz="{handle}"/><geometry><box size="0.02 0.02 0.15"/></geometry></visual>
  </link>
  <joint name="hinge" type="revolute"><parent link="body"/><child link="door"/>
    <origin xyz="{door_origin}"/><axis xyz="0 0 {axis_sign}"/>
    <limit lower="{lower}" upper="{upper}" effort="10" velocity="1"/></joint>
  {empty}
</robot>
"""


def make(tmp_path: Path, text: str, name: str = "cab.urdf", **task) -> OpenArticulatedEnv:
    path = tmp_path / name
    path.write_text(text)
    return OpenArticulatedEnv(task={"object": str(path), **STILL, **task}, obs_mode="state")


def test_a_link_without_geometry_loads_and_the_task_steps(tmp_path: Path) -> None:
    env = make(tmp_path, cabinet_urdf(extra_link=True))
    try:
        env.reset(seed=0)
        env.step(np.zeros(env.action_space.shape, dtype=np.float32))
        assert env.object.grasp_source == "name"
        # the frame fixed to the door is part of the door: parts are 0 (base) and 1 (joint 0)
        lut = env.object.segmentation_lut[0]
        assert sorted(set(lut[lut >= 0].tolist())) == [0, 1] and env.object.child_parts == [1]
    finally:
        env.close()


def test_closed_at_the_upper_limit_is_found_and_the_state_grows_while_opening(tmp_path: Path) -> None:
    # The same door with its hinge axis turned around: it opens as the position goes to -1.5.
    env = make(tmp_path, cabinet_urdf(lower=-1.5, upper=0.0, axis_sign=-1.0))
    try:
        obj = env.object
        assert obj.open_sign.tolist() == [-1.0] and obj.closed_qpos.tolist() == [0.0]
        assert obj.limits.tolist() == [[0.0, 1.5]]
        _, info = env.reset(seed=0), env.evaluate()
        assert 0.0 <= float(info["joint_state"][0, 0]) <= 0.05 * 1.5 + 1e-6
        import torch

        env.articulation.set_qpos(torch.tensor([[-1.0]]))
        info = env.evaluate()
        assert float(info["joint_state"][0, 0]) == pytest.approx(1.0, abs=1e-5)
        assert float(info["open_fraction"][0]) == pytest.approx(1.0 / 1.5, abs=1e-5)
        # the reported axis is turned with the state: +z opens it, as for the procedural door
        assert float(info["joint_axis"][0, 0, 2]) == pytest.approx(1.0, abs=1e-5)
    finally:
        env.close()
    forced = make(tmp_path, cabinet_urdf(), name="forced.urdf", closed="upper")
    try:
        assert forced.object.open_sign.tolist() == [-1.0]
    finally:
        forced.close()


def _door_in_cloud(env: OpenArticulatedEnv) -> tuple[int, np.ndarray, float]:
    """From the camera's cloud: the door's point count, its panel normal (world xy, unit) and how far
    its centroid is in front of (-x) the rest of the object's, metres."""
    pc = env.get_obs()["pointcloud"]
    labels = pc["part_label"][0].cpu().numpy()
    pts = pc["xyzw"][0, :, :3].cpu().numpy()
    part = env.object.child_parts[env.object.target_joint]
    door, rest = pts[labels == part], pts[(labels >= 0) & (labels != part)]
    if len(door) < 30:
        return len(door), np.zeros(2), 0.0
    centred = door - door.mean(axis=0)
    normal = np.linalg.eigh(centred.T @ centred)[1][:, 0]
    return len(door), normal[:2] / np.linalg.norm(normal[:2]), float(rest[:, 0].mean() - door[:, 0].mean())


def test_front_yaw_turns_the_object_to_the_robot(tmp_path: Path) -> None:
    path = tmp_path / "side.urdf"
    path.write_text(cabinet_urdf(front="+y"))
    seen = {}
    for front in ("+y", "-y", None):
        env = OpenArticulatedEnv(task={"object": str(path), "front_yaw": front, **STILL},
                                 obs_mode="pointcloud")
        try:
            env.reset(seed=0)
            seen[front] = _door_in_cloud(env)
        finally:
            env.close()
    for front in ("+y", None):  # told, or guessed from the moving part: the door faces the robot
        count, normal, ahead = seen[front]
        assert count > 200 and abs(normal[0]) > 0.98 and ahead > 0.1
    count, _, ahead = seen["-y"]  # told the wrong side, it faces away: hidden behind the body
    assert count < 30 or ahead < 0


def test_the_front_is_guessed_from_the_moving_part(tmp_path: Path) -> None:
    env = make(tmp_path, cabinet_urdf(front="+y"))
    try:
        assert env.object.front_yaw == pytest.approx(np.pi / 2)  # front normal +y turned to -x
    finally:
        env.close()


def test_a_missing_mesh_names_the_urdf_the_link_and_the_folder(tmp_path: Path) -> None:
    path = tmp_path / "cab.urdf"
    path.write_text(cabinet_urdf(mesh="meshes/body.stl"))
    with pytest.raises(ObjectFileError, match=r"cab\.urdf: link 'body': mesh 'meshes/body.stl' not found"):
        prepare_object_file(path)


def test_package_and_relative_mesh_paths_resolve(tmp_path: Path) -> None:
    pkg = tmp_path / "my_cabinet"
    (pkg / "meshes").mkdir(parents=True)
    (pkg / "urdf").mkdir()
    trimesh.creation.box(extents=[0.3, 0.4, 0.5]).export(pkg / "meshes" / "body.stl")
    path = pkg / "urdf" / "cab.urdf"
    path.write_text(cabinet_urdf(mesh="package://my_cabinet/meshes/body.stl"))
    prepared = prepare_object_file(path)
    assert str(pkg / "meshes" / "body.stl") in prepared.urdf_path.read_text()
    rel = pkg / "cab_rel.urdf"
    rel.write_text(cabinet_urdf(mesh="meshes/body.stl"))
    assert str(pkg / "meshes" / "body.stl") in prepare_object_file(rel).urdf_path.read_text()


def test_a_malformed_file_names_the_file_and_the_line(tmp_path: Path) -> None:
    path = tmp_path / "broken.urdf"
    path.write_text(cabinet_urdf().replace("</robot>", ""))
    with pytest.raises(ObjectFileError, match=r"broken\.urdf: malformed XML at line \d+"):
        prepare_object_file(path)


def test_a_mimic_joint_is_dropped_with_a_warning(tmp_path: Path) -> None:
    path = tmp_path / "mimic.urdf"
    path.write_text(cabinet_urdf().replace('<axis xyz="0 0 1.0"/>',
                                           '<axis xyz="0 0 1.0"/><mimic joint="other" multiplier="1"/>'))
    prepared = prepare_object_file(path)
    assert any("mimic" in w for w in prepared.warnings)
    assert "mimic" not in prepared.urdf_path.read_text()


def test_urdf_friction_becomes_a_capped_drive_and_part_mass_is_set(tmp_path: Path) -> None:
    text = cabinet_urdf().replace("</joint>", '<dynamics damping="0.1" friction="0.4"/></joint>', 1)
    env = make(tmp_path, text, part_mass=0.25)
    try:
        joint = env.object.joints[0]
        assert float(joint.force_limit[0]) == pytest.approx(0.4 + 0.1, rel=1e-4)
        assert float(env.object.target_child_link.mass[0]) == pytest.approx(0.25, rel=1e-4)
    finally:
        env.close()


def test_a_part_of_a_few_grams_is_given_the_least_mass_a_held_part_stays_still_with(tmp_path: Path) -> None:
    """Held open in the fingers, an 11 g sash (Meta-World's window) was pushed about by the contact
    solver and never counted as at rest: a part lighter than MIN_PART_MASS gets that mass, with a
    warning; ``part_mass`` still sets any mass."""
    from capt_env.tasks.object_loading import MIN_PART_MASS

    light = cabinet_urdf().replace('<mass value="0.5"/>', '<mass value="0.011"/>')
    env = make(tmp_path, light)
    try:
        assert float(env.object.target_child_link.mass[0]) == pytest.approx(MIN_PART_MASS, rel=1e-4)
        assert any("weighs 0.011 kg" in w for w in env.object.warnings)
    finally:
        env.close()
    env = make(tmp_path, light, part_mass=0.02)
    try:
        assert float(env.object.target_child_link.mass[0]) == pytest.approx(0.02, rel=1e-4)
    finally:
        env.close()


def test_cylinder_and_capsule_geometry_lies_along_the_urdf_axis(tmp_path: Path) -> None:
    """ManiSkill's trimesh conversion turns SAPIEN's x-axis cylinders and capsules by 90 degrees;
    the task's own geometry must not: a 30 cm bar along the door's z stays 30 cm tall."""
    from capt_env.objects.link_geometry import collision_shape_meshes, link_vertices

    text = cabinet_urdf().replace(
        '<visual name="pull_bar"><origin xyz="-0.03 0.35 0"/><geometry><box size="0.02 0.02 0.15"/>'
        "</geometry></visual>",
        '<visual name="pull_bar"><origin xyz="-0.03 0.35 0"/><geometry><cylinder radius="0.01" length="0.3"/>'
        '</geometry></visual><collision><origin xyz="-0.03 0.35 0"/><geometry><capsule radius="0.01" '
        'length="0.3"/></geometry></collision>')
    assert "cylinder" in text
    env = make(tmp_path, text)
    try:
        door = env.object.target_child_link
        verts = link_vertices(door)
        bar = verts[verts[:, 0] < -0.015]
        assert bar[:, 2].max() - bar[:, 2].min() == pytest.approx(0.3, abs=1e-3)
        capsule = min(collision_shape_meshes(door), key=lambda m: m.vertices[:, 0].mean())
        assert np.ptp(capsule.vertices[:, 2]) == pytest.approx(0.32, abs=2e-3)  # 0.3 + two 1 cm caps
    finally:
        env.close()


def test_a_continuous_joint_loads_with_a_full_turn_of_range(tmp_path: Path) -> None:
    text = cabinet_urdf().replace('type="revolute"', 'type="continuous"').replace(
        '<limit lower="0.0" upper="1.5" effort="10" velocity="1"/>', '<limit effort="10" velocity="1"/>')
    assert 'type="continuous"' in text
    env = make(tmp_path, text)
    try:
        assert env.object.limits.tolist() == [[0.0, pytest.approx(2 * np.pi)]]
        env.reset(seed=1)
    finally:
        env.close()


def test_a_large_file_placed_by_default_is_moved_until_its_handle_lies_where_the_panda_reaches(
        tmp_path: Path) -> None:
    # twice the size: 60 cm deep, centred at 0.3 m its handle stands under the resting hand and 70
    # cm to the side; placed by default it is moved towards the Panda's reach (x to USER_GRASP_X[0],
    # |y| to USER_GRASP_MAX_Y), placed by hand it is not; either way it is then moved straight away
    # from the robot until it clears the resting arm, so the handle ends in front of the hand
    from capt_env.tasks.config import RESTING_ARM_FRONT_X, USER_GRASP_MAX_Y, USER_GRASP_X
    closed = {"scale": 2.0, "target_init_fraction": [0.0, 0.0]}
    env = make(tmp_path, cabinet_urdf(), **closed)
    told = make(tmp_path, cabinet_urdf(), name="told.urdf", object_xy=[0.3, 0.0], **closed)
    try:
        env.reset(seed=0)
        told.reset(seed=0)
        x, y = env.object_batch.grasp_point()[0, :2].tolist()
        x0, y0 = told.object_batch.grasp_point()[0, :2].tolist()
        dx, dy = env.object.placement_shift
        assert dx > 0.0 and abs(y0) > USER_GRASP_MAX_Y
        assert abs(y) == pytest.approx(USER_GRASP_MAX_Y, abs=1e-3)
        assert min(x, x0) > max(USER_GRASP_X[0], RESTING_ARM_FRONT_X)  # clear of the resting hand
        assert told.object.placement_shift == (0.0, 0.0)
    finally:
        env.close()
        told.close()


def test_a_handle_already_within_reach_leaves_the_placement_as_it_is() -> None:
    from capt_env.tasks.object_loading import grasp_reach_shift
    aabb = (np.array([-0.1, -0.1, 0.0]), np.array([0.1, 0.1, 0.2]))
    # front turned to -x (yaw 0): a handle 12 cm before the centre at x 0.3 lies at 0.18
    assert grasp_reach_shift(np.array([-0.12, 0.05, 0.1]), aabb, 0.0, (0.3, 0.0)) == (0.0, 0.0)
    dx, dy = grasp_reach_shift(np.array([-0.12, 0.05, 0.1]), aabb, np.pi / 2, (0.3, 0.3))
    # turned a quarter: the handle lies at (0.25, 0.18): 1 cm too far
    assert dx == pytest.approx(-0.01) and dy == 0.0
