"""ManiSkill3 task: a Panda arm on a table opens one articulated object seen by depth cameras.

**Task.** A Panda (control mode ``pd_ee_delta_pose`` by default; any Panda mode can be passed)
stands at the table edge; an articulated object (a procedural category instance, or a user URDF/MJCF
file) stands on the table with its front to the robot. The robot must open the target joint: swing
the door/lid about its hinge, or pull the drawer.

**Randomisations** (per episode, from the episode seed; see :class:`TaskConfig`):
- the object instance (drawn from the configured split or id list; a new one each reconfiguration,
  which by default happens every reset when ``num_envs == 1``); with ``num_envs > 1`` each sub-scene
  draws its own instance from its episode RNG (:mod:`capt_env.tasks.object_batch`; a user file is
  the same file in every sub-scene);
- the object's position on the table (+-``object_xy_noise``) and yaw (+-``yaw_noise``);
- the target joint's initial state (fraction ``target_init_fraction`` of its range) and the other
  joints' states (``other_init_fraction``);
- each camera's eye position (+-``jitter`` metres per axis), always looking at the object;
- the robot's initial joint positions (Gaussian noise ``robot_init_qpos_noise`` rad).

**Joint states.** Every joint's state is 0 closed and grows while opening, in radians or metres:
for a file whose part is closed at its upper limit the simulator position is turned around
(``LoadedObject.sim_qpos`` / ``task_state``), and so is the reported axis.

**Success.** The target joint is past ``success_fraction`` (default 0.75) of its range, measured from
the closed state, and its child link is at rest.

**Reward.** Dense: ``reach + 2 * progress + 2 * success`` where ``reach = 1 - tanh(5 d)`` with
``d`` the gripper-to-grasp-point distance in metres (held at 1 once the part has moved),
``progress = clip(open_fraction / success_fraction, 0, 1)``. Normalised dense: the same / 5.

**Ground truth.** ``info`` holds, for every movable joint of each sub-scene's object (leading
``num_envs`` dimension, then the joint slot; world frame): ``joint_type`` (0 revolute, 1 prismatic),
``joint_axis`` (unit, +state opens), ``joint_pivot`` (a point on the axis: the joint frame origin),
``joint_state`` (rad or m), ``joint_limits``, ``joint_child_part``, ``joint_mask`` (which slots hold
a joint: sub-scenes whose instances have fewer joints than the batch's most are padded, see
:mod:`capt_env.tasks.object_batch`), plus per sub-scene ``target_joint`` (a slot index),
``open_fraction``, ``grasp_point``, ``target_link_pos`` (the target part's centre of mass, metres:
which part the task means, as ManiSkill's TurnFaucet gives it; not where its joint or handle is),
``success``.
The cameras look at the object's bounding-box centre from fixed offsets; a reset that leaves the
grasp point outside every camera's picture (a large object) warns once per env
(:class:`UnseenGraspPointWarning`; :meth:`OpenArticulatedEnv.grasp_point_views`).
In ``pointcloud`` mode the observation's ``pointcloud`` dict also carries ``part_label``: for each
point the object part it lies on (0 = everything fixed to the base, ``k + 1`` = the part movable
joint ``k`` moves, links joined by fixed joints counted as one part), or -1 for anything that is not
the object.
"""

from __future__ import annotations

import dataclasses
import warnings
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np
import sapien
import torch
from gymnasium.utils import seeding as gym_seeding
from mani_skill.agents.robots import Panda
from mani_skill.envs.sapien_env import BaseEnv
from mani_skill.sensors.camera import CameraConfig as MSCameraConfig
from mani_skill.utils import sapien_utils
from mani_skill.utils.scene_builder.table import TableSceneBuilder
from mani_skill.utils.structs import Articulation, Pose

from capt_common.typed_yaml import from_dict
from capt_env.registration import GENERIC_ID
from capt_env.rendering import translate_render_error
from capt_env.tasks.camera_view import in_picture, step_back_to_see
from capt_env.tasks.config import (
    RESTING_ARM_BOTTOM_Z,
    RESTING_ARM_CLEARANCE,
    RESTING_ARM_FRONT_X,
    RESTING_ARM_HALF_Y,
    TaskConfig,
    read_task_yaml,
)
from capt_env.tasks.object_batch import ObjectBatch, load_objects
from capt_env.tasks.object_loading import LoadedObject

JOINT_TYPE_IDS = {"revolute": 0, "prismatic": 1}
# End-effector deltas: [-1, 1] maps to +-0.1 m / +-0.1 rad per 20 Hz control step (ManiSkill 3.0.1
# applies the rotation part with a negative scale: a +1 rotation action turns by -0.1 rad).
DEFAULT_CONTROL_MODE = "pd_ee_delta_pose"
ROBOT_BASE_XY = (-0.615, 0.0)


class UnseenGraspPointWarning(UserWarning):
    """A reset left the target part's grasp point outside every task camera's picture."""


@dataclass(frozen=True)
class GraspPointView:
    """One camera's view of the grasp points: ``seen`` (num_envs,) bool, ``step_back_m`` (num_envs,)
    how far it must move back along its line of sight to see each (0 where it does)."""

    camera: str
    seen: np.ndarray
    step_back_m: np.ndarray


@dataclass(frozen=True)
class _Placement:
    """Where the object's root goes and what the cameras look at, world frame (per env)."""

    root_p: torch.Tensor  # (b, 3) metres
    root_q: torch.Tensor  # (b, 4) wxyz
    centre: torch.Tensor  # (b, 3) object bounding-box centre, metres


def clear_of_resting_arm(lo: np.ndarray, hi: np.ndarray, yaw: np.ndarray, root_p: np.ndarray) -> np.ndarray:
    """How far (b,) metres along world +x each object must move so that its bounding box (``lo``,
    ``hi`` (b, 3), object frame), turned by ``yaw`` (b,) rad about +z with its root at ``root_p``
    (b, 3), clears the Panda's resting arm by :data:`~capt_env.tasks.config.RESTING_ARM_CLEARANCE`:
    0 for a box wholly below the arm's lowest point or beside it, else the distance that puts the
    box's near face that far in front of the arm's front (the robot is at -x, facing +x)."""
    lo, hi = np.asarray(lo, dtype=np.float64), np.asarray(hi, dtype=np.float64)
    corners = np.stack([np.stack([np.where(m & 1, hi[:, 0], lo[:, 0]), np.where(m & 2, hi[:, 1], lo[:, 1])],
                                 axis=-1) for m in range(4)], axis=1)  # (b, 4, 2) footprint
    c, s = np.cos(yaw)[:, None], np.sin(yaw)[:, None]
    x = c * corners[..., 0] - s * corners[..., 1] + root_p[:, 0:1]
    y = s * corners[..., 0] + c * corners[..., 1] + root_p[:, 1:2]
    top = hi[:, 2] + root_p[:, 2]
    in_reach = (top > RESTING_ARM_BOTTOM_Z) & (y.min(axis=1) < RESTING_ARM_HALF_Y) & (
        y.max(axis=1) > -RESTING_ARM_HALF_Y)
    needed = RESTING_ARM_FRONT_X + RESTING_ARM_CLEARANCE - x.min(axis=1)
    return np.where(in_reach, np.maximum(needed, 0.0), 0.0)


def _yaw_quat(yaw: torch.Tensor) -> torch.Tensor:
    """(b,) yaw in radians -> (b, 4) wxyz quaternions about world +z."""
    half = yaw / 2
    zeros = torch.zeros_like(half)
    return torch.stack([torch.cos(half), zeros, zeros, torch.sin(half)], dim=-1)


class OpenArticulatedEnv(BaseEnv):
    """Open an articulated object with a Panda. See the module docstring for the full description."""

    SUPPORTED_ROBOTS = ["panda"]
    SUPPORTED_OBS_MODES = ("none", "state", "state_dict", "pointcloud", "sensor_data", "rgb", "depth",
                           "rgbd", "rgb+depth", "rgb+depth+segmentation", "rgb+segmentation",
                           "depth+segmentation", "segmentation")
    agent: Panda

    def __init__(
        self,
        *args: Any,
        robot_uids: str = "panda",
        robot_init_qpos_noise: float = 0.02,
        task: TaskConfig | dict | None = None,
        reconfiguration_freq: int | None = None,
        num_envs: int = 1,
        **kwargs: Any,
    ) -> None:
        overrides = {k: kwargs.pop(k) for k in list(kwargs) if k in _TASK_FIELDS}
        where = "task"
        if isinstance(task, (str, Path)):  # a YAML file of TaskConfig keys
            where = str(task)
            task = read_task_yaml(task)
        if isinstance(task, TaskConfig):
            base = dataclasses.asdict(task)
            base["cameras"] = list(task.cameras)
        else:
            base = dict(task or {})
        for key, value in overrides.items():  # the id's own keys (a category id's category)
            if value is None:
                continue
            if key in base and base[key] is not None and base[key] != value:
                raise ValueError(f"{where}: {key}={base[key]!r} conflicts with this env id's "
                                 f"{key}={value!r}; use {GENERIC_ID} for any {key}")
            if key == "category" and base.get("object") is not None:
                raise ValueError(f"{where}: object={base['object']!r} on a category id; use {GENERIC_ID} "
                                 "for user files")
            base[key] = value
        self.task_config: TaskConfig = from_dict(TaskConfig, base, where=where)
        self.robot_init_qpos_noise = robot_init_qpos_noise
        self.object_batch: ObjectBatch | None = None  # the object of every sub-scene, set in _load_scene
        if reconfiguration_freq is None:
            reconfiguration_freq = 1 if num_envs == 1 else 0
        kwargs.setdefault("control_mode", DEFAULT_CONTROL_MODE)
        if "render_backend" not in kwargs and not torch.cuda.is_available():
            kwargs["render_backend"] = "cpu"  # ManiSkill asks for CUDA first and warns on every env
        self._entropy_seed_pending = False
        self.sensors_on_next_obs = True  # see get_obs
        self._held_obs: dict[bool | None, Any] = {}
        self.warn_unseen_grasp_point = True  # see _warn_if_no_camera_sees_the_grasp_point
        self._warned_unseen_grasp = False  # the constructor's own reset may warn first
        with translate_render_error():
            super().__init__(
                *args,
                robot_uids=robot_uids,
                reconfiguration_freq=reconfiguration_freq,
                num_envs=num_envs,
                **kwargs,
            )
        self._entropy_seed_pending = True  # the constructor's own reset used ManiSkill's fixed seed

    def reset(self, seed: int | list[int] | None = None, options: dict | None = None) -> tuple[Any, dict]:
        if seed is None and self._entropy_seed_pending:
            # Gymnasium's rule: the first unseeded reset draws fresh entropy, so processes differ
            seed = int(np.random.SeedSequence().entropy % (2**31))
        self._entropy_seed_pending = False
        if seed is not None:
            # Gymnasium's own generator (env.np_random), seeded like ManiSkill's episode RNGs.
            first = int(seed[0]) if isinstance(seed, (list, tuple, np.ndarray)) else int(seed)
            self._np_random, self._np_random_seed = gym_seeding.np_random(first)
        obs, info = super().reset(seed=seed, options=options)
        self._warn_if_no_camera_sees_the_grasp_point()
        return obs, info

    # ------------------------------------------------------------------ scene
    @property
    def _default_sensor_configs(self) -> list[MSCameraConfig]:
        x, y = self.task_config.placement_xy()
        target = np.array([x, y, 0.15])
        configs = []
        for cam in self.task_config.cameras:
            eye = target + np.asarray(cam.eye)
            pose = sapien_utils.look_at(eye=eye.tolist(), target=target.tolist())
            configs.append(
                MSCameraConfig(cam.name, pose=pose, width=cam.width, height=cam.height, fov=cam.fov,
                               near=cam.near, far=cam.far)
            )
        return configs

    @property
    def _default_human_render_camera_configs(self) -> MSCameraConfig:
        pose = sapien_utils.look_at(eye=[-0.9, -0.9, 0.9], target=[0.1, 0.0, 0.15])
        return MSCameraConfig("render_camera", pose=pose, width=512, height=512, fov=1.0, near=0.01,
                              far=100)

    def _load_agent(self, options: dict) -> None:
        super()._load_agent(options, sapien.Pose(p=[*ROBOT_BASE_XY, 0.0]))

    def _load_scene(self, options: dict) -> None:
        self.table_scene = TableSceneBuilder(self, robot_init_qpos_noise=self.robot_init_qpos_noise)
        self.table_scene.build()
        instance_id = options.get("instance_id") if options else None
        self.object_batch = load_objects(self.scene, self.task_config, self._batched_episode_rng.rngs,
                                         instance_id)

    @property
    def object(self) -> LoadedObject | None:
        """The object every sub-scene holds (None before the scene is built).

        :raises RuntimeError: if the sub-scenes hold different instances (``num_envs > 1``): use
            ``object_batch`` (``object_batch.objects[i]`` is sub-scene i's).
        """
        batch = self.object_batch
        if batch is None:
            return None
        if not batch.shared:
            raise RuntimeError("the sub-scenes hold different objects (instances "
                               f"{batch.instance_ids}); use env.object_batch")
        return batch.objects[0]

    @property
    def articulation(self) -> Articulation:
        """The object being opened (ManiSkill articulation, batched over sub-scenes: a merged view
        when they hold different instances, qpos padded to the most joints)."""
        assert self.object_batch is not None
        return self.object_batch.articulation

    # ---------------------------------------------------------------- episode
    def _initialize_episode(self, env_idx: torch.Tensor, options: dict) -> None:
        cfg = self.task_config
        batch = self.object_batch
        rows = env_idx.cpu().numpy()
        b, dof = len(rows), batch.max_dof
        with torch.device(self.device):
            self.table_scene.initialize(env_idx)
            rng = self._batched_episode_rng[env_idx]
            noise_xy = np.stack([rng.uniform(-n, n) for n in cfg.object_xy_noise], axis=-1)
            yaw = batch.front_yaw[rows] + rng.uniform(-cfg.yaw_noise, cfg.yaw_noise)
            placement = self._placement(rows, torch.as_tensor(noise_xy, dtype=torch.float32),
                                        torch.as_tensor(yaw, dtype=torch.float32))
            self.articulation.set_pose(Pose.create_from_pq(p=placement.root_p, q=placement.root_q))

            span = batch.limits[rows, :, 1] - batch.limits[rows, :, 0]
            frac = np.stack([rng.uniform(*cfg.other_init_fraction) for _ in range(dof)], axis=-1)
            frac[np.arange(b), batch.target_joint[rows]] = rng.uniform(*cfg.target_init_fraction)
            qpos = batch.sim_qpos(frac.reshape(b, dof) * span, rows)
            self.articulation.set_qpos(torch.as_tensor(qpos, dtype=torch.float32))
            self.articulation.set_qvel(torch.zeros((b, dof)))
            self._aim_cameras(rows, placement, np.asarray(yaw, dtype=np.float64).reshape(b))

    def _placement(self, rows: np.ndarray, noise_xy: torch.Tensor, yaw: torch.Tensor) -> _Placement:
        """Root poses putting the bounding-box centre of the objects of sub-scenes ``rows`` (b,) at
        ``placement_xy()`` + the object's ``placement_shift`` + ``noise_xy`` (b, 2) on the table,
        turned by ``yaw`` (b,) radians, then moved along +x clear of the resting arm
        (:func:`clear_of_resting_arm`)."""
        lo, hi = self.object_batch.aabb[rows, 0], self.object_batch.aabb[rows, 1]  # (b, 3) object frame
        centre_local = torch.as_tensor((lo + hi) / 2, dtype=torch.float32)
        shift = torch.as_tensor(self.object_batch.placement_shift[rows], dtype=torch.float32)
        target_xy = torch.as_tensor(self.task_config.placement_xy(), dtype=torch.float32) + shift + noise_xy
        c, s = torch.cos(yaw), torch.sin(yaw)
        rot_cx = c * centre_local[:, 0] - s * centre_local[:, 1]
        rot_cy = s * centre_local[:, 0] + c * centre_local[:, 1]
        z = torch.as_tensor(-lo[:, 2] + 1e-3, dtype=torch.float32)
        root_p = torch.stack([target_xy[:, 0] - rot_cx, target_xy[:, 1] - rot_cy, z], dim=-1)
        away = torch.as_tensor(clear_of_resting_arm(lo, hi, yaw.cpu().numpy(), root_p.cpu().numpy()),
                               dtype=torch.float32)
        root_p[:, 0] += away
        centre = torch.stack([target_xy[:, 0] + away, target_xy[:, 1], z + centre_local[:, 2]], dim=-1)
        return _Placement(root_p=root_p, root_q=_yaw_quat(yaw), centre=centre)

    def _aim_cameras(self, rows: np.ndarray, placement: _Placement, yaw: np.ndarray) -> None:
        """Point every camera of sub-scenes ``rows`` (b,) at their object's centre, drawing each
        sub-scene's eye from its own episode RNG.

        ``yaw`` (b,) is each object's yaw; its front then faces world direction ``yaw - front_yaw``
        rotated from +x, i.e. towards the robot (-x) up to the yaw noise.
        """
        centres = placement.centre.cpu().numpy().astype(np.float64)
        for j, i in enumerate(int(r) for r in rows):
            rng, target = self._batched_episode_rng[i], centres[j]
            front = float(yaw[j]) - self.object_batch.front_yaw[i] + np.pi  # azimuth of the front normal
            for cam in self.task_config.cameras:
                if cam.name not in self._sensors:
                    continue
                if cam.random_view:
                    dist = float(rng.uniform(*cam.distance))
                    az = front + float(rng.uniform(*cam.azimuth))
                    el = float(rng.uniform(*cam.elevation))
                    offset = dist * np.array([np.cos(el) * np.cos(az), np.cos(el) * np.sin(az), np.sin(el)])
                else:
                    offset = np.asarray(cam.eye, dtype=np.float64)
                    offset = offset + np.asarray(rng.uniform(-cam.jitter, cam.jitter, size=3)).reshape(3)
                pose = sapien_utils.look_at(eye=(target + offset).tolist(), target=target.tolist())
                _set_camera_pose(self._sensors[cam.name].camera, i, pose.sp)

    # ------------------------------------------------------------ evaluation
    def joint_ground_truth(self) -> dict[str, torch.Tensor]:
        """World-frame ground truth of every joint slot of every sub-scene, (num_envs, J, ...): see
        the module docstring."""
        batch = self.object_batch
        axes, pivots = batch.joint_frames()
        return {
            "joint_type": batch.tensor("joint_type").clone(),
            "joint_axis": axes,
            "joint_pivot": pivots,
            "joint_state": batch.task_state(self.articulation.qpos),
            "joint_limits": batch.tensor("limits", torch.float32).clone(),
            "joint_child_part": batch.tensor("child_parts").clone(),
            "joint_mask": batch.tensor("joint_mask").clone(),
        }

    def grasp_point(self) -> torch.Tensor:
        """(num_envs, 3) world-frame grasp point on each target part (handle centre or far edge), metres."""
        return self.object_batch.grasp_point()

    def target_link_position(self) -> torch.Tensor:
        """(num_envs, 3) world-frame centre of mass of each target joint's child link, metres: which
        part to open when an object has several alike (a double door's leaves), the way ManiSkill's
        TurnFaucet names its target switch (``target_link_pos``). It says nothing of where the part's
        joint or handle is."""
        link = self.object_batch.target_link
        return (link.pose * link.cmass_local_pose).p

    def grasp_point_views(self) -> list[GraspPointView]:
        """For each camera, whether each sub-scene's grasp point (:meth:`grasp_point`) is inside its
        picture and how far (m) it must move back along its line of sight for it to be
        (:mod:`capt_env.tasks.camera_view`). A handle no camera sees cannot be perceived."""
        grasp = self.grasp_point().cpu().numpy().astype(np.float64)
        views = []
        for name, sensor in self._sensors.items():
            k = sensor.camera.get_intrinsic_matrix().cpu().numpy()
            ext = sensor.camera.get_extrinsic_matrix().cpu().numpy()
            w, h = sensor.config.width, sensor.config.height
            seen = np.array([bool(in_picture(g[None], k[i], ext[i], w, h)[0]) for i, g in enumerate(grasp)])
            back = np.array([step_back_to_see(g[None], k[i], ext[i], w, h) for i, g in enumerate(grasp)])
            views.append(GraspPointView(name, seen, back))
        return views

    def _warn_if_no_camera_sees_the_grasp_point(self) -> None:
        """Warn once per env when a reset leaves some sub-scene's grasp point outside every camera's
        picture (a large object seen from the default eyes): perception cannot find that handle.
        ``warn_unseen_grasp_point = False`` silences it (dataset generation: a random view that
        misses the handle is a training sample like any other)."""
        if self._warned_unseen_grasp or not self.warn_unseen_grasp_point or not self._sensors:
            return
        views = self.grasp_point_views()
        unseen = ~np.any([v.seen for v in views], axis=0)
        if not unseen.any():
            return
        grasp = self.grasp_point().cpu().numpy().astype(np.float64)
        self._warned_unseen_grasp = True
        i = int(np.flatnonzero(unseen)[0])
        what = self.task_config.object or self.task_config.category
        moves = ", ".join(f"{v.camera} by {v.step_back_m[i]:.2f} m" for v in views)
        warnings.warn(f"{what}: no camera sees the target part's grasp point "
                      f"{np.round(grasp[i], 3).tolist()} (world, m), so a "
                      f"perceived estimate cannot find its handle; a camera sees it moved back along its "
                      f"line of sight ({moves}; the task's cameras: eye)", UnseenGraspPointWarning,
                      stacklevel=3)

    def evaluate(self) -> dict[str, torch.Tensor]:
        cfg = self.task_config
        batch = self.object_batch
        gt = self.joint_ground_truth()
        lo, hi = batch.target_values(gt["joint_limits"]).unbind(-1)  # (num_envs,) each
        open_fraction = (batch.target_values(gt["joint_state"]) - lo) / (hi - lo)
        child = batch.target_link
        at_rest = (torch.linalg.norm(child.linear_velocity, dim=-1) <= cfg.rest_linear_speed) & (
            torch.linalg.norm(child.angular_velocity, dim=-1) <= cfg.rest_angular_speed
        )
        opened = open_fraction >= cfg.success_fraction
        return {
            **gt,
            "target_joint": batch.tensor("target_joint").clone(),
            "open_fraction": open_fraction,
            "grasp_point": self.grasp_point(),
            "target_link_pos": self.target_link_position(),
            "opened": opened,
            "success": opened & at_rest,
        }

    def _get_obs_extra(self, info: dict) -> dict[str, torch.Tensor]:
        obs = {"tcp_pose": self.agent.tcp.pose.raw_pose}
        if "state" in self.obs_mode:
            obs.update(
                grasp_point=info["grasp_point"],
                tcp_to_grasp=info["grasp_point"] - self.agent.tcp.pose.p,
                target_qpos=self.object_batch.target_values(
                    self.object_batch.task_state(self.articulation.qpos)).unsqueeze(-1),
                open_fraction=info["open_fraction"].unsqueeze(-1),
            )
        return obs

    def get_obs(self, info: dict | None = None, unflattened: bool = False) -> Any:
        """ManiSkill's observation, plus ``part_label`` in pointcloud mode. With
        ``sensors_on_next_obs`` set False by a caller that will not look at the cameras on the next
        step (the perception wrapper between its looks), that step returns the last rendered
        observation again instead of rendering: rendering does not change the simulation, so the
        episode is the same, only the unused cloud is stale. The flag resets to True each time."""
        renders = self._obs_mode not in ("none", "state", "state_dict")
        # flattening changes a sensor observation only when it carries a state vector
        key = unflattened if self.obs_mode_struct.state else None
        skip, self.sensors_on_next_obs = not self.sensors_on_next_obs, True
        if skip and renders and key in self._held_obs:
            return self._held_obs[key]
        obs = self._rendered_obs(info, unflattened)
        if renders:
            self._held_obs = {key: obs}
        return obs

    def _rendered_obs(self, info: dict | None, unflattened: bool) -> Any:
        obs = super().get_obs(info, unflattened)
        if self.obs_mode == "pointcloud" and isinstance(obs, dict) and "pointcloud" in obs:
            seg = obs["pointcloud"]["segmentation"][..., 0].long()
            obs["pointcloud"]["part_label"] = self.part_labels_from_segmentation(seg)
        if isinstance(obs, dict):
            # ManiSkill leaves an empty "sensor_data" dict in pointcloud mode; Gymnasium forbids empty Dicts.
            obs = {k: v for k, v in obs.items() if not (isinstance(v, dict) and len(v) == 0)}
        return obs

    def part_labels_from_segmentation(self, seg: torch.Tensor) -> torch.Tensor:
        """Map simulator per-scene segmentation ids (num_envs, N) to object part labels (num_envs, N),
        each sub-scene by its own object's table; -1 = not object."""
        lut = self.object_batch.segmentation_lut.to(seg.device)
        clipped = seg.clamp(0, lut.shape[-1] - 1)
        labels = torch.gather(lut.expand(seg.shape[0], -1), 1, clipped)
        return torch.where(seg < lut.shape[-1], labels, torch.full_like(labels, -1))

    def compute_dense_reward(self, obs: Any, action: torch.Tensor, info: dict) -> torch.Tensor:
        dist = torch.linalg.norm(self.agent.tcp.pose.p - info["grasp_point"], dim=-1)
        reach = 1 - torch.tanh(5 * dist)
        progress = (info["open_fraction"] / self.task_config.success_fraction).clamp(0, 1)
        reach = torch.where(progress > 0.02, torch.ones_like(reach), reach)
        return reach + 2 * progress + 2 * info["success"].float()

    def compute_normalized_dense_reward(self, obs: Any, action: torch.Tensor, info: dict) -> torch.Tensor:
        return self.compute_dense_reward(obs=obs, action=action, info=info) / 5.0


def _set_camera_pose(camera: Any, scene_idx: int, pose: sapien.Pose) -> None:
    """Set the pose of sub-scene ``scene_idx``'s copy of an unmounted ManiSkill camera
    (``RenderCamera``; its own ``set_local_pose`` sets every sub-scene's) and drop the poses and
    matrices it caches from them."""
    camera._render_cameras[scene_idx].set_local_pose(pose)
    camera._cached_local_pose = None
    camera._cached_model_matrix = None


_TASK_FIELDS = {f.name for f in dataclasses.fields(TaskConfig)}
