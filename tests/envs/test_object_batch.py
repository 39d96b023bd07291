"""One object per sub-scene (``capt_env.tasks.object_batch``). ManiSkill 3.0.1 refuses
``num_envs > 1`` on the CPU simulator, so the per-sub-scene build is checked on a bare scene of
several CPU sub-scenes (the task's own build path: ``set_scene_idxs`` per sub-scene, then the merged
views); the full batched env runs on a GPU only (marked ``gpu``)."""

from __future__ import annotations

import numpy as np
import pytest
import torch

from capt_env.objects.registry import make_object
from capt_env.objects.scene import create_scene
from capt_env.objects.splits import instance_ids
from capt_env.tasks.config import TaskConfig
from capt_env.tasks.object_batch import load_objects
from capt_env.wrappers.batched_oracle_observation import ground_truth

CABINETS = TaskConfig(category="drawer_cabinet")


def _rngs(*seeds: int) -> list[np.random.RandomState]:
    return [np.random.RandomState(s) for s in seeds]


def _drawer_ids_by_count() -> dict[int, int]:
    """A train drawer cabinet with 1, 2 and 3 drawers (the first of each)."""
    found: dict[int, int] = {}
    for iid in instance_ids("drawer_cabinet", "train"):
        found.setdefault(len(make_object("drawer_cabinet", iid).joints), iid)
    return found


def test_sub_scenes_draw_their_own_instances_deterministically():
    seeds = (11, 12, 13)
    batch = load_objects(create_scene(num_scenes=3), CABINETS, _rngs(*seeds))
    allowed = instance_ids("drawer_cabinet", "train")
    assert not batch.shared and len(set(batch.instance_ids)) == 3
    # sub-scene i's id is one draw of its own RNG from the split
    assert batch.instance_ids == [allowed[np.random.RandomState(s).randint(len(allowed))] for s in seeds]
    again = load_objects(create_scene(num_scenes=3), CABINETS, _rngs(*seeds))
    assert again.instance_ids == batch.instance_ids
    other = load_objects(create_scene(num_scenes=3), CABINETS, _rngs(21, 22, 23))
    assert other.instance_ids != batch.instance_ids


def test_per_sub_scene_ground_truth_matches_each_instance_spec():
    by_count = _drawer_ids_by_count()
    ids = [by_count[1], by_count[3], by_count[2]]
    scene = create_scene(num_scenes=3)
    batch = load_objects(scene, CABINETS, _rngs(0, 1, 2), instance_id=ids)
    specs = [make_object("drawer_cabinet", i) for i in ids]
    assert batch.instance_ids == ids and batch.max_dof == 3 and batch.articulation.max_dof == 3
    assert list(scene.state_dict_registry.articulations) == ["object"]  # one state row per sub-scene
    assert batch.joint_mask.tolist() == [[True, False, False], [True, True, True], [True, True, False]]
    axes, pivots = batch.joint_frames()  # every root at its sub-scene's origin, every joint closed
    grasp = batch.grasp_point()
    for i, spec in enumerate(specs):
        dof = len(spec.joints)
        assert batch.target_joint[i] == spec.joint_index(spec.target_joint)
        assert batch.joint_type[i].tolist() == [1] * dof + [-1] * (3 - dof)
        assert batch.child_parts[i].tolist() == list(range(1, dof + 1)) + [-1] * (3 - dof)
        assert batch.limits[i, :dof] == pytest.approx(np.array([j.limits for j in spec.joints]))
        assert np.all(batch.limits[i, dof:] == 0)
        assert batch.aabb[i] == pytest.approx(np.stack(spec.aabb()))
        assert batch.grasp_local[i] == pytest.approx(spec.grasp_point)
        assert batch.objects[i].joint_names == [j.name for j in spec.joints]
        for k, joint in enumerate(spec.joints):
            assert axes[i, k].tolist() == pytest.approx(joint.axis, abs=1e-6)
            assert pivots[i, k].tolist() == pytest.approx(joint.origin, abs=1e-6)
        assert torch.all(axes[i, dof:] == 0) and torch.all(pivots[i, dof:] == 0)
        assert grasp[i].tolist() == pytest.approx(spec.grasp_point, abs=1e-6)
        # part labels: sub-scene i's segmentation ids map to its own links' parts
        lut = batch.segmentation_lut[i]
        for link in batch.objects[i].articulation.links:
            part = spec.link_index(link.name)  # drawer k is moved by joint k - 1
            assert int(lut[int(link.per_scene_id[0])]) == part


def test_joint_frames_follow_each_sub_scene_and_padded_states_stay_zero():
    by_count = _drawer_ids_by_count()
    ids = [by_count[2], by_count[1]]
    batch = load_objects(create_scene(num_scenes=2), CABINETS, _rngs(0, 1), instance_id=ids)
    state = np.array([[0.05, 0.1], [0.08, 0.0]])
    qpos = batch.sim_qpos(state, np.arange(2))
    assert qpos[1, 1] == 0.0  # sub-scene 1 has one drawer
    assert batch.task_state(torch.as_tensor(qpos, dtype=torch.float32)).numpy() == pytest.approx(
        np.array([[0.05, 0.1], [0.08, 0.0]]), abs=1e-6)
    for i, obj in enumerate(batch.objects):  # CPU views read one sub-scene: set each on its own
        obj.articulation.set_qpos(torch.as_tensor(qpos[i, : obj.dof], dtype=torch.float32)[None])
    axes, pivots = batch.joint_frames()
    for i, obj in enumerate(batch.objects):
        for k, joint in enumerate(obj.spec.joints):  # a drawer's frame slides out along its axis
            moved = np.asarray(joint.origin) + state[i, k] * np.asarray(joint.axis)
            assert pivots[i, k].tolist() == pytest.approx(moved.tolist(), abs=1e-5)
    target = batch.target_values(torch.as_tensor(state))
    assert target.tolist() == [state[i, batch.target_joint[i]] for i in range(2)]


def test_one_id_a_user_file_or_one_sub_scene_share_one_object(tmp_path):
    shared = load_objects(create_scene(num_scenes=2), CABINETS, _rngs(0, 1), instance_id=5)
    assert shared.shared and shared.instance_ids == [5, 5]
    assert shared.articulation is shared.objects[0].articulation and len(shared.articulation._objs) == 2
    single = load_objects(create_scene(), CABINETS, _rngs(0))
    assert single.shared and single.articulation.name == "object"
    allowed = instance_ids("drawer_cabinet", "train")
    assert single.instance_ids == [allowed[np.random.RandomState(0).randint(len(allowed))]]
    with pytest.raises(ValueError, match="2 ids for 3 sub-scenes"):
        load_objects(create_scene(num_scenes=3), CABINETS, _rngs(0, 1, 2), instance_id=[1, 2])
    with pytest.raises(ValueError, match="not among the allowed"):
        load_objects(create_scene(num_scenes=2), TaskConfig(category="drawer_cabinet", split="test"),
                     _rngs(0, 1), instance_id=[0, 1])


def test_single_env_holds_one_shared_object_drawn_by_its_seed():
    import gymnasium as gym

    import capt_env  # noqa: F401

    env = gym.make("CaptOpenDrawerCabinet-ms-v0", obs_mode="state")
    base = env.unwrapped
    allowed = instance_ids("drawer_cabinet", "train")
    for seed in (0, 5):
        _, info = env.reset(seed=seed)
        batch = base.object_batch
        assert batch.shared and base.object is batch.objects[0]
        assert batch.instance_ids == [allowed[np.random.RandomState(seed).randint(len(allowed))]]
        assert info["joint_mask"].tolist() == [[True] * base.object.dof]
        assert info["target_joint"].tolist() == [base.object.target_joint]
    env.close()


def test_batched_ground_truth_picks_each_sub_scenes_target_slot():
    """``BatchedOracleObservation`` reads padded per-sub-scene info: row 0 opens slot 0 of one joint,
    row 1 slot 2 of three."""
    axes = torch.zeros(2, 3, 3)
    axes[0, 0] = torch.tensor([0.0, 0.0, 1.0])
    axes[1] = torch.tensor([[1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [-1.0, 0.0, 0.0]])
    info = {"joint_type": torch.tensor([[0, -1, -1], [1, 1, 1]]), "joint_axis": axes,
            "joint_pivot": torch.zeros(2, 3, 3),
            "joint_state": torch.tensor([[0.3, 0.0, 0.0], [0.0, 0.0, 0.1]]),
            "target_joint": torch.tensor([0, 2]),
            "grasp_point": torch.tensor([[0.5, 0.0, 0.2], [0.0, 0.0, 0.2]]),
            "joint_mask": torch.tensor([[True, False, False], [True, True, True]])}
    gt = ground_truth(info)
    assert gt["prismatic"].tolist() == [False, True]
    assert gt["direction"].tolist() == [[0.0, 0.0, 1.0], [-1.0, 0.0, 0.0]]
    assert gt["state"].tolist() == pytest.approx([0.3, 0.1])


@pytest.mark.gpu
def test_gpu_env_holds_one_instance_per_sub_scene():
    """The batched env on ManiSkill's GPU simulation: per-sub-scene instances, ground truth and part
    labels, the same instances for the same seed, new ones at a reconfiguration, and PPO's vector env
    stepping over it."""
    import gymnasium as gym

    import capt_env  # noqa: F401
    from agents.ppo.maniskill_vec_env import ManiSkillVecEnv
    from capt_env.wrappers.batched_oracle_observation import BatchedOracleObservation

    n = 4
    env = gym.make("CaptOpenDrawerCabinet-ms-v0", num_envs=n, sim_backend="physx_cuda", obs_mode="pointcloud")
    base = env.unwrapped
    obs, info = env.reset(seed=3, options={"reconfigure": True})  # (built at construction from seeds 2022+)
    batch = base.object_batch
    first = batch.instance_ids
    assert len(set(first)) > 1 and not batch.shared
    assert info["joint_axis"].shape == (n, batch.max_dof, 3)
    assert info["target_joint"].tolist() == batch.target_joint.tolist()
    assert info["joint_mask"].cpu().numpy().tolist() == batch.joint_mask.tolist()
    for i, obj in enumerate(batch.objects):
        k = obj.target_joint
        yaw = float(torch.atan2(info["joint_axis"][i, k, 1], info["joint_axis"][i, k, 0]))
        assert abs(abs(yaw) - np.pi) < base.task_config.yaw_noise + 1e-3  # a drawer opens towards -x
        labels = obs["pointcloud"]["part_label"][i]
        assert set(labels.unique().tolist()) <= set(range(-1, obj.dof + 1))
    _, info = env.reset(seed=3, options={"reconfigure": True})
    assert base.object_batch.instance_ids == first
    _, info = env.reset(seed=4, options={"reconfigure": True})
    assert base.object_batch.instance_ids != first
    env.close()

    env = gym.make("CaptOpenDrawerCabinet-ms-v0", num_envs=n, sim_backend="physx_cuda", obs_mode="state")
    venv = ManiSkillVecEnv(BatchedOracleObservation(env, {"source": "oracle"}), reconfigure_every=3)
    venv.reset()
    for _ in range(5):
        venv.step_async(np.zeros((n, 7), np.float32))
        obs, rewards, dones, _ = venv.step_wait()
        assert obs.shape[0] == n and np.isfinite(obs).all() and np.isfinite(rewards).all()
    venv.close()
