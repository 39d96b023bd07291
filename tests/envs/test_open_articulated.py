"""The opening task: Gymnasium compliance, determinism, physics-checked ground truth, bad inputs."""

from __future__ import annotations

import gymnasium as gym
import numpy as np
import pytest
import torch
from gymnasium.utils.env_checker import check_env

import capt_env  # noqa: F401 - registers the env ids
from capt_common.typed_yaml import ConfigError
from capt_env.objects.registry import CATEGORIES
from capt_env.registration import GENERIC_ID, env_id

CAMERA = {"name": "depth_camera", "eye": [-0.45, -0.3, 0.45], "width": 96, "height": 96}


def make(category: str, **kwargs) -> gym.Env:
    task = {"cameras": [CAMERA], "split": "test", **kwargs.pop("task", {})}
    return gym.make(env_id(category), obs_mode=kwargs.pop("obs_mode", "pointcloud"), task=task, **kwargs)


def rotate_about_line(points: np.ndarray, axis: np.ndarray, pivot: np.ndarray, angle: float) -> np.ndarray:
    """Rodrigues rotation of (N, 3) points about the line (axis, pivot) by ``angle`` radians."""
    k = axis / np.linalg.norm(axis)
    v = points - pivot
    cos, sin = np.cos(angle), np.sin(angle)
    rotated = v * cos + np.cross(k, v) * sin + np.outer(v @ k, k) * (1 - cos)
    return rotated + pivot


def nearest_distance(a: np.ndarray, b: np.ndarray) -> np.ndarray:
    """For each point of ``a``, the distance to the nearest point of ``b`` (metres)."""
    d = torch.cdist(torch.as_tensor(a), torch.as_tensor(b))
    return d.min(dim=1).values.numpy()


@pytest.mark.parametrize("category", CATEGORIES)
def test_env_checker_pointcloud(category: str) -> None:
    env = make(category)
    try:
        check_env(env, skip_render_check=True)
        obs, info = env.reset(seed=3)
        pc = obs["pointcloud"]
        assert pc["xyzw"].shape[0] == CAMERA["width"] * CAMERA["height"]
        assert pc["part_label"].shape == (pc["xyzw"].shape[0],)
        assert (pc["part_label"] >= 0).sum() > 100, "the camera must see the object"
        assert info["joint_axis"].shape[-1] == 3
        np.testing.assert_allclose(np.linalg.norm(info["joint_axis"], axis=-1), 1.0, atol=1e-5)
    finally:
        env.close()


def test_same_seed_same_object_and_cloud() -> None:
    clouds = []
    for _ in range(2):
        env = make("laptop")
        obs, info = env.reset(seed=11)
        clouds.append((obs["pointcloud"]["xyzw"].copy(), env.unwrapped.object.instance_id))
        env.close()
    assert clouds[0][1] == clouds[1][1]
    np.testing.assert_allclose(clouds[0][0], clouds[1][0], atol=1e-6)


def _child_points(env: gym.Env, child: int) -> np.ndarray:
    obs = env.unwrapped.get_obs()
    pc = obs["pointcloud"]
    labels = pc["part_label"][0].cpu().numpy()
    xyz = pc["xyzw"][0, :, :3].cpu().numpy()
    return xyz[labels == child].astype(np.float64)


def _moved(points: np.ndarray, jtype: int, axis: np.ndarray, pivot: np.ndarray, delta: float) -> np.ndarray:
    """Where ``points`` go when the joint (axis, pivot) moves by ``delta`` (rad or m)."""
    if jtype == 0:
        return rotate_about_line(points, axis, pivot, delta)
    return points + delta * axis / np.linalg.norm(axis)


def _motion_matrix(jtype: int, axis: np.ndarray, pivot: np.ndarray, delta: float) -> np.ndarray:
    """4x4 rigid motion of a joint move by ``delta`` about/along the line (axis, pivot)."""
    m = np.eye(4)
    if jtype == 0:
        rot = rotate_about_line(np.eye(3), axis, np.zeros(3), delta).T
        m[:3, :3] = rot
        m[:3, 3] = pivot - rot @ pivot
    else:
        m[:3, 3] = delta * axis / np.linalg.norm(axis)
    return m


def _quat_matrix(q: tuple[float, float, float, float]) -> np.ndarray:
    w, x, y, z = q
    return np.array([
        [1 - 2 * (y * y + z * z), 2 * (x * y - w * z), 2 * (x * z + w * y)],
        [2 * (x * y + w * z), 1 - 2 * (x * x + z * z), 2 * (y * z - w * x)],
        [2 * (x * z - w * y), 2 * (y * z + w * x), 1 - 2 * (x * x + y * y)],
    ])


def distance_to_boxes(points: np.ndarray, boxes) -> np.ndarray:
    """Distance (m) from (N, 3) link-frame points to the nearest surface of a link's boxes."""
    best = np.full(len(points), np.inf)
    for box in boxes:
        local = (points - np.asarray(box.pos)) @ _quat_matrix(box.quat)
        q = np.abs(local) - np.asarray(box.half_size)
        outside = np.linalg.norm(np.maximum(q, 0), axis=1)
        inside = np.minimum(q.max(axis=1), 0)
        best = np.minimum(best, np.abs(outside + inside))
    return best


def _tilted(axis: np.ndarray, angle: float) -> np.ndarray:
    """``axis`` tilted by ``angle`` radians towards a fixed perpendicular direction."""
    perp = np.cross(axis, [0.0, 0.0, 1.0] if abs(axis[2]) < 0.9 else [1.0, 0.0, 0.0])
    perp /= np.linalg.norm(perp)
    return np.cos(angle) * axis + np.sin(angle) * perp


@pytest.mark.parametrize("category", CATEGORIES)
def test_physics_checked_labels(category: str) -> None:
    """Move the target joint in the simulator; the child part's points must move as the GT axis says.

    Two checks: (1) exact, with correspondences: the labelled points, carried by the simulator's own
    child-link motion, land where the GT axis and state change predict (< 0.1 mm); (2) rendered: in
    the cloud re-rendered after the move, the child points lie on the child's boxes (median < 2 mm)
    when the boxes are placed by the GT motion, and at least 2x farther (mean) under a wrong hypothesis
    (flipped sign, axis tilted 10 deg, pivot shifted 2 cm).
    """
    close_camera = {"name": "depth_camera", "eye": [-0.25, -0.25, 0.4], "width": 128, "height": 128}
    task = {"target_init_fraction": [0.4, 0.4], "other_init_fraction": [0.5, 0.5], "cameras": [close_camera]}
    env = make(category, task=task)
    try:
        _, info = env.reset(seed=5)
        base = env.unwrapped
        k = int(info["target_joint"])
        child = int(info["joint_child_part"][k])
        jtype = int(info["joint_type"][k])
        axis, pivot = info["joint_axis"][k].astype(np.float64), info["joint_pivot"][k].astype(np.float64)
        lo, hi = (float(v) for v in info["joint_limits"][k])
        delta = 0.2 * (hi - lo) if jtype == 1 else min(0.35, 0.2 * (hi - lo))
        link = base.articulation.links[child]
        before = _child_points(env, child)
        pose_before = link.pose.to_transformation_matrix()[0].cpu().numpy().astype(np.float64)
        qpos = base.articulation.qpos.clone()
        qpos[0, k] += delta
        base.articulation.set_qpos(qpos)
        after = _child_points(env, child)
        pose_after = link.pose.to_transformation_matrix()[0].cpu().numpy().astype(np.float64)
        expected_state = float(info["joint_state"][k]) + delta
        assert float(base.articulation.qpos[0, k]) == pytest.approx(expected_state, abs=1e-4)
        assert len(before) > 50 and len(after) > 50, f"{category}: the camera must see the moving part"

        predicted = _moved(before, jtype, axis, pivot, delta)
        motion = pose_after @ np.linalg.inv(pose_before)
        carried = before @ motion[:3, :3].T + motion[:3, 3]
        np.testing.assert_allclose(carried, predicted, atol=1e-4)

        boxes = base.object.spec.links[child].boxes

        def surface_error(hyp_axis: np.ndarray, hyp_pivot: np.ndarray) -> np.ndarray:
            """Distance (m) of the re-rendered child points to the child's boxes, placed by a hypothesis."""
            gt_motion = _motion_matrix(jtype, hyp_axis, hyp_pivot, delta)
            link_pose = gt_motion @ pose_before
            local = (after - link_pose[:3, 3]) @ link_pose[:3, :3]
            return distance_to_boxes(local, boxes)

        err = surface_error(axis, pivot)
        assert np.median(err) < 0.002 and np.percentile(err, 90) < 0.005, (
            f"{category}: re-rendered points are {np.median(err) * 1000:.1f} mm (median) off the part"
        )
        shift = np.cross(axis, _tilted(axis, np.pi / 2))
        wrong = {"flipped sign": (-axis, pivot), "tilted 10 deg": (_tilted(axis, np.radians(10)), pivot)}
        if jtype == 0:
            wrong["pivot +2 cm"] = (axis, pivot + 0.02 * shift)
        for name, (a, p) in wrong.items():
            assert np.mean(surface_error(a, p)) > 2 * np.mean(err), (
                f"{category}: the check cannot tell the GT axis from one {name}"
            )
    finally:
        env.close()


@pytest.mark.parametrize("category", ["oven", "drawer_cabinet"])
def test_part_labels_agree_with_simulator_segmentation(category: str) -> None:
    env = make(category)
    try:
        obs, _ = env.reset(seed=2)
        base = env.unwrapped
        seg = obs["pointcloud"]["segmentation"][:, 0]
        labels = obs["pointcloud"]["part_label"]
        links = list(base.articulation.links)
        id_map = base.segmentation_id_map
        for seg_id in np.unique(seg):
            entity = id_map.get(int(seg_id))
            got = np.unique(labels[seg == seg_id])
            assert len(got) == 1
            if entity is not None and any(entity is link for link in links):
                assert links[int(got[0])].name == entity.name
            else:
                assert got[0] == -1
    finally:
        env.close()


def test_state_mode_steps_and_rewards() -> None:
    env = make("drawer_cabinet", obs_mode="state")
    try:
        obs, info = env.reset(seed=0)
        assert obs.ndim == 1 and np.all(np.isfinite(obs))
        for _ in range(3):
            obs, reward, terminated, truncated, info = env.step(env.action_space.sample())
            assert 0.0 <= float(reward) <= 5.0
        assert 0.0 <= float(info["open_fraction"]) < 0.75
        assert not bool(info["success"])
    finally:
        env.close()


def test_success_when_opened_and_at_rest() -> None:
    env = make("cabinet_door", obs_mode="state")
    try:
        _, info = env.reset(seed=1)
        base = env.unwrapped
        k = int(info["target_joint"])
        lo, hi = info["joint_limits"][k]
        qpos = base.articulation.qpos.clone()
        qpos[0, k] = float(lo + 0.9 * (hi - lo))
        base.articulation.set_qpos(qpos)
        ev = base.evaluate()
        assert bool(ev["opened"][0]) and bool(ev["success"][0])
        assert float(ev["open_fraction"][0]) == pytest.approx(0.9, abs=1e-3)
    finally:
        env.close()


def test_generic_id_takes_category() -> None:
    env = gym.make(GENERIC_ID, obs_mode="state", task={"category": "oven", "cameras": [CAMERA]})
    try:
        env.reset(seed=0)
        assert env.unwrapped.object.category == "oven"
    finally:
        env.close()


def test_placement_defaults_per_category_and_task_overrides() -> None:
    from capt_env.tasks.config import TaskConfig

    assert TaskConfig(category="oven").placement_xy() == (0.3, 0.0)
    assert TaskConfig(category="laptop").placement_xy() == (-0.08, 0.0)
    assert TaskConfig(category="laptop", object_xy=(0.2, 0.1)).placement_xy() == (0.2, 0.1)
    env = gym.make(GENERIC_ID, obs_mode="state",
                   task={"category": "laptop", "object_xy_noise": [0.0, 0.0], "yaw_noise": 0.0,
                         "cameras": [CAMERA]})
    try:
        env.reset(seed=0)
        lo, hi = env.unwrapped.object.aabb
        root = env.unwrapped.articulation.pose.p[0].cpu().numpy()
        np.testing.assert_allclose(root[:2] + (np.asarray(lo) + np.asarray(hi))[:2] / 2, [-0.08, 0.0],
                                   atol=1e-5)
    finally:
        env.close()


def test_object_moved_clear_of_the_resting_arm() -> None:
    """A box reaching the resting arm's space is moved straight away from the robot until its near face
    is the clearance in front of the arm; a box below the arm's lowest point, beside it, or already
    clear stays; a turned box is judged by its turned footprint."""
    from capt_env.tasks.config import RESTING_ARM_CLEARANCE, RESTING_ARM_FRONT_X
    from capt_env.tasks.open_articulated import clear_of_resting_arm

    lo, hi = np.array([[-0.2, -0.3, 0.0]]), np.array([[0.2, 0.3, 0.6]])  # 40 x 60 x 60 cm
    front = RESTING_ARM_FRONT_X + RESTING_ARM_CLEARANCE

    def away(root_x: float, root_y: float = 0.0, yaw: float = 0.0, top: float = 0.6) -> float:
        box_hi = hi.copy()
        box_hi[0, 2] = top
        return float(clear_of_resting_arm(lo, box_hi, np.array([yaw]), np.array([[root_x, root_y, 0.0]]))[0])

    assert away(0.2) == pytest.approx(front)  # near face at x = 0, against the hand
    assert away(0.25) == pytest.approx(front - 0.05)
    assert away(0.5) == 0.0  # already clear
    assert away(0.2, top=0.1) == 0.0  # a laptop-low box under the hand
    assert away(0.2, root_y=0.6) == 0.0  # beside the arm
    assert away(0.3, yaw=np.pi / 2) == pytest.approx(front)  # turned, 60 cm deep: near face at x = 0


@pytest.mark.parametrize(("category", "seeds"), [("oven", (400, 404, 405)), ("washing_machine", (418, 420))])
def test_resting_arm_starts_clear_of_a_deep_object(category: str, seeds: tuple[int, ...]) -> None:
    """No link of the resting arm presses on the object at reset: at the default placement these
    resets of deep ovens and washing machines started with links 6-7 or the hand against the door."""
    env = gym.make(env_id(category), obs_mode="state", task={"cameras": [CAMERA]})
    try:
        for seed in seeds:
            env.reset(seed=seed)
            env.step(np.zeros(env.action_space.shape, dtype=np.float32))
            pressing = []
            for contact in env.unwrapped.scene.get_contacts():
                names = [body.entity.name for body in contact.bodies]
                if ("panda" in names[0]) == ("panda" in names[1]):
                    continue  # not robot-object
                if any(np.linalg.norm(p.impulse) > 1e-4 or p.separation < 0.0 for p in contact.points):
                    pressing.append(names)
            assert not pressing, (seed, pressing)
    finally:
        env.close()


def test_bad_inputs_give_clear_errors(tmp_path) -> None:
    with pytest.raises(ConfigError, match="unknown category"):
        gym.make(GENERIC_ID, task={"category": "toaster"})
    with pytest.raises(ConfigError, match="exactly one"):
        gym.make(GENERIC_ID, task={})
    with pytest.raises(ConfigError, match="target_init_fraction"):
        make("laptop", task={"target_init_fraction": [0.5, 1.5]})
    with pytest.raises(ConfigError, match="unknown key"):
        make("laptop", task={"colour": "red"})
    with pytest.raises(ConfigError, match="at least one camera"):
        make("laptop", task={"cameras": []})
    with pytest.raises(ConfigError, match="object_xy"):
        make("laptop", task={"object_xy": [0.1, 0.2, 0.3]})
    with pytest.raises(FileNotFoundError, match="missing.urdf"):
        gym.make(GENERIC_ID, task={"object": str(tmp_path / "missing.urdf")})
    with pytest.raises(ValueError, match="instance_id"):
        env = make("laptop")
        try:
            env.reset(seed=0, options={"reconfigure": True, "instance_id": 10**6})
        finally:
            env.close()


def test_user_urdf_object_with_named_joint(tmp_path) -> None:
    from capt_env.objects.registry import make_object
    from capt_env.objects.user_files import spec_to_urdf

    spec = make_object("cabinet_door", 3)
    path = tmp_path / "door.urdf"
    path.write_text(spec_to_urdf(spec))
    env = gym.make(GENERIC_ID, obs_mode="state", task={"object": str(path), "joint": spec.target_joint})
    try:
        _, info = env.reset(seed=0)
        obj = env.unwrapped.object
        assert obj.category == "user"
        assert obj.joint_names[obj.target_joint].endswith(spec.target_joint)
        np.testing.assert_allclose(np.linalg.norm(info["joint_axis"], axis=-1), 1.0, atol=1e-5)
    finally:
        env.close()
    with pytest.raises(ValueError, match="no_such_joint"):
        gym.make(GENERIC_ID, obs_mode="state", task={"object": str(path), "joint": "no_such_joint"})


def test_info_names_the_target_part_by_its_centre_of_mass(tmp_path) -> None:
    """``target_link_pos`` is the target drawer's centre: each drawer of a stack at its own height,
    nearer its own handle than half the spacing between drawers (what tells the leaves of a double
    door, or the drawers of a stack, apart)."""
    from capt_env.objects.registry import make_object
    from capt_env.objects.splits import instance_ids
    from capt_env.objects.user_files import spec_to_urdf

    spec = next(s for s in (make_object("drawer_cabinet", i) for i in instance_ids("drawer_cabinet", "train"))
                if len(s.joints) == 3)
    path = tmp_path / "stack.urdf"
    path.write_text(spec_to_urdf(spec))
    heights = []
    for joint in spec.joints:
        env = gym.make(GENERIC_ID, obs_mode="state", task={"object": str(path), "joint": joint.name,
                                                            "cameras": [CAMERA]})
        try:
            _, info = env.reset(seed=0)
            centre = np.asarray(info["target_link_pos"]).reshape(3)
            grasp = np.asarray(info["grasp_point"]).reshape(3)
            heights.append((float(centre[2]), float(grasp[2])))
        finally:
            env.close()
    centres = [c for c, _ in heights]
    assert centres == sorted(centres)  # drawers are numbered bottom up
    spacing = min(np.diff(centres))
    assert all(abs(c - g) < spacing / 2 for c, g in heights)
