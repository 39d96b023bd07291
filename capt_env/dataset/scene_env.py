"""The scene ``capt generate`` renders when its ``variation`` changes the scene
(``Variation.needs_scene``): the opening task's scene (table, Panda, object, one depth camera; see
:class:`capt_env.tasks.open_articulated.OpenArticulatedEnv`) with

- the object's geometry varied (``variation.geometry``, procedural categories; built once per
  reconfiguration, like the instance);
- distractor primitives on the table (``variation.distractors``): drawn per reconfiguration, placed
  per view around the object's footprint at that view's joint states;
- the camera where the task's robot cameras stand (``variation.viewpoints.mode == "robot"``).

One sub-scene on the CPU; all randomness comes from the episode RNG, so a view is a pure function of
its reset seed (and its instance). World frame, metres, radians.
"""

from __future__ import annotations

from typing import Any

import gymnasium as gym
import numpy as np
import sapien
import torch
from mani_skill.utils import sapien_utils
from mani_skill.utils.scene_builder.table import TableSceneBuilder

from capt_env.dataset.distractors import Primitive, build_primitive, draw_primitives, place
from capt_env.dataset.variation import Variation
from capt_env.objects.geometry import quat_from_axis_angle
from capt_env.objects.link_geometry import link_vertices
from capt_env.objects.registry import make_object
from capt_env.tasks.object_batch import shared_batch
from capt_env.tasks.object_loading import choose_instance, load_procedural
from capt_env.tasks.open_articulated import OpenArticulatedEnv, _Placement, _set_camera_pose

HIDDEN_Z = -5.0  # m, where distractors that are not placed wait (below the table and the floor)


class GenerateSceneEnv(OpenArticulatedEnv):
    """The task's scene varied for dataset generation (see the module docstring). ``variation``
    is a :class:`capt_env.dataset.variation.Variation`; everything else is the task's."""

    def __init__(self, *args: Any, variation: Variation | None = None, **kwargs: Any) -> None:
        if kwargs.get("num_envs", 1) != 1:
            raise ValueError("the generation scene has one sub-scene")
        self.variation = variation or Variation()
        self._primitives: list[Primitive] = []
        self._distractors: list[Any] = []
        self._link_vertices: list[np.ndarray] | None = None
        super().__init__(*args, **kwargs)

    # ------------------------------------------------------------------ scene
    def _load_scene(self, options: dict) -> None:
        cfg, geometry = self.task_config, self.variation.geometry
        if cfg.category is None or not geometry.enabled:
            super()._load_scene(options)
        else:  # the task's own scene with the varied spec of the instance it would draw
            self.table_scene = TableSceneBuilder(self, robot_init_qpos_noise=self.robot_init_qpos_noise)
            self.table_scene.build()
            iid = choose_instance(cfg, self._batched_episode_rng.rngs[0], (options or {}).get("instance_id"))
            obj = load_procedural(self.scene, cfg, iid, spec=make_object(cfg.category, iid, geometry))
            self.object_batch = shared_batch(obj, 1, torch.device(self.scene.device or "cpu"))
        rng = self._batched_episode_rng[0]
        self._primitives = draw_primitives(self.variation.distractors, rng)
        colours = [tuple(float(c) for c in rng.uniform(0.1, 0.9, 3)) for _ in self._primitives]
        self._distractors = [build_primitive(self.scene, prim, f"distractor_{k}", colour)
                             for k, (prim, colour) in enumerate(zip(self._primitives, colours, strict=True))]
        self._link_vertices = None

    def distractor_segmentation_ids(self) -> np.ndarray:
        """(D,) int64 per-scene segmentation ids of the distractors (empty without any)."""
        return np.array([int(a.per_scene_id.reshape(-1)[0]) for a in self._distractors], dtype=np.int64)

    def object_footprint(self) -> tuple[np.ndarray, np.ndarray]:
        """Table-plane bounds (lo (2,), hi (2,)) of every object link's render vertices at the
        current joint states and pose, metres."""
        links = list(self.object_batch.articulation.links)
        if self._link_vertices is None:
            self._link_vertices = [link_vertices(link) for link in links]
        pts = []
        for link, verts in zip(links, self._link_vertices, strict=True):
            if len(verts):
                mat = np.asarray(link.pose.to_transformation_matrix().reshape(-1, 4, 4)[0].cpu(), np.float64)
                pts.append(verts @ mat[:3, :3].T + mat[:3, 3])
        xy = np.concatenate(pts)[:, :2]
        return xy.min(axis=0), xy.max(axis=0)

    # ---------------------------------------------------------------- episode
    def _initialize_episode(self, env_idx: torch.Tensor, options: dict) -> None:
        super()._initialize_episode(env_idx, options)
        if not self._distractors:
            return
        cfg = self.variation.distractors
        rng = self._batched_episode_rng[0]
        count = int(rng.randint(cfg.count[0], cfg.count[1] + 1))
        spots = place(self._primitives, count, self.object_footprint(), cfg, rng)
        for k, (actor, prim, spot) in enumerate(zip(self._distractors, self._primitives, spots, strict=True)):
            if spot is None:
                pose = sapien.Pose(p=[0.0, 0.0, HIDDEN_Z - k])
            else:
                q = quat_from_axis_angle((0.0, 0.0, 1.0), float(spot[2]))
                pose = sapien.Pose(p=[float(spot[0]), float(spot[1]), prim.half_height + 1e-3],
                                   q=[float(v) for v in q])
            actor.set_pose(pose)

    def _aim_cameras(self, rows: np.ndarray, placement: _Placement, yaw: np.ndarray) -> None:
        """The task's aim (``ring``), or with ``robot`` viewpoints each camera at one of the task's
        eyes (relative to the object's centre, world axes) plus a uniform jitter per axis."""
        view = self.variation.viewpoints
        if view.mode == "ring":
            super()._aim_cameras(rows, placement, yaw)
            return
        centres = placement.centre.cpu().numpy().astype(np.float64)
        for j, i in enumerate(int(r) for r in rows):
            rng, target = self._batched_episode_rng[i], centres[j]
            for cam in self.task_config.cameras:
                eye = np.asarray(view.eyes[int(rng.randint(len(view.eyes)))], dtype=np.float64)
                eye = eye + np.asarray(rng.uniform(-view.jitter, view.jitter, size=3)).reshape(3)
                pose = sapien_utils.look_at(eye=(target + eye).tolist(), target=target.tolist())
                _set_camera_pose(self._sensors[cam.name].camera, i, pose.sp)


def make_generate_env(task: dict, variation: Variation) -> gym.Env:
    """The single-env (numpy, unbatched) generation scene of ``task`` (TaskConfig keys) in
    ``pointcloud`` mode, never reconfigured unless a reset asks."""
    from mani_skill.utils.wrappers.gymnasium import CPUGymWrapper

    from capt_env.registration import OwnedArrays

    env = GenerateSceneEnv(num_envs=1, obs_mode="pointcloud", task=task, variation=variation,
                           reconfiguration_freq=0)
    return OwnedArrays(CPUGymWrapper(env))
