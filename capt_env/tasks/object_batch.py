"""The task's object in every sub-scene, as one batch: what the task knows about each sub-scene's
object as arrays with a leading ``num_envs`` dimension, and merged simulator views that read all
sub-scenes at once.

**Which object where.** With ``num_envs == 1``, a user ``object`` file, or a reset that names one
``instance_id``, one object is built into every sub-scene (:func:`shared_batch`). With a procedural
category and ``num_envs > 1`` each sub-scene ``i`` holds its own instance: drawn from the task's
allowed ids (``split`` or ``instance_ids``) by sub-scene ``i``'s episode RNG, so independently per
sub-scene and the same for the same reset seed (two sub-scenes may draw the same id), built into
sub-scene ``i`` only (``set_scene_idxs([i])``) and merged into one articulation view, as ManiSkill's
``OpenCabinetDrawerEnv`` does (:func:`merged_batch`). ``reset(options={"reconfigure": True,
"instance_id": [id_0, ..., id_{n-1}]})`` picks one id per sub-scene.

**Joint slots.** Slot ``k`` is the ``k``-th movable joint (qpos order) of each sub-scene's object.
Instances of one category can differ in joint count (a drawer cabinet has 1-3 drawers) and in
target joint (which drawer, which temple), so ``J`` is the largest count and a sub-scene's missing
slots are padded as in the dataset shards: ``joint_mask`` False, joint type -1, child part -1,
limits (0, 0), axis, pivot and state 0. The merged articulation's qpos is padded to ``J`` the same
way (ManiSkill pads to ``max_dof``); padded columns are written as 0 and never read.

Units: metres, radians. "Object frame": an object's root frame at its closed state.
"""

from __future__ import annotations

from collections.abc import Callable, Sequence
from dataclasses import dataclass
from functools import cached_property
from typing import Any

import numpy as np
import torch
from mani_skill.utils.structs import Articulation, ArticulationJoint, Link

from capt_env.tasks.config import TaskConfig
from capt_env.tasks.object_loading import LoadedObject, choose_instance, load_object, load_procedural

InstanceChoice = int | Sequence[int] | None
"""A reset's ``instance_id`` option: none (draw), one id for every sub-scene, or one per sub-scene."""


@dataclass(frozen=True)
class JointSlot:
    """Joint slot ``k`` in the sub-scenes that have it: a joint view whose rows are those sub-scenes."""

    joint: ArticulationJoint  # merged over ``rows`` (or one joint built into every sub-scene)
    rows: torch.Tensor  # (n,) long: the sub-scene of each of the view's rows


@dataclass(frozen=True)
class ObjectBatch:
    """One object per sub-scene (see the module docstring). Arrays have ``num_envs`` rows."""

    objects: tuple[LoadedObject, ...]  # sub-scene i's object (the same one repeated when shared)
    articulation: Articulation  # all sub-scenes' objects: qpos (num_envs, J), root pose (num_envs, 7)
    slots: tuple[JointSlot, ...]  # J joint slots
    grasp_link: Link  # each sub-scene's grasp link, (num_envs) rows
    target_link: Link  # each sub-scene's target joint's child link, (num_envs) rows
    shared: bool  # one object built into every sub-scene
    device: torch.device

    @property
    def num_envs(self) -> int:
        return len(self.objects)

    @property
    def max_dof(self) -> int:
        """J: the most movable joints any sub-scene's object has."""
        return len(self.slots)

    @property
    def instance_ids(self) -> list[int]:
        """Each sub-scene's procedural instance id (-1 for a user file)."""
        return [obj.instance_id for obj in self.objects]

    # --------------------------------------------------------- per-sub-scene facts, numpy
    @cached_property
    def joint_mask(self) -> np.ndarray:
        """(num_envs, J) bool: which slots hold a joint."""
        return self._pad(lambda o: np.ones(o.dof), False, bool)

    @cached_property
    def joint_type(self) -> np.ndarray:
        """(num_envs, J) int64: 0 revolute, 1 prismatic, -1 no joint."""
        return self._pad(lambda o: o.joint_type_ids, -1, np.int64)

    @cached_property
    def limits(self) -> np.ndarray:
        """(num_envs, J, 2) float64 task limits (0, range), radians or metres; (0, 0) where no joint."""
        return self._pad(lambda o: o.limits, 0.0, np.float64)

    @cached_property
    def closed_qpos(self) -> np.ndarray:
        """(num_envs, J) float64 simulator position of each joint's closed limit (0 where no joint)."""
        return self._pad(lambda o: o.closed_qpos, 0.0, np.float64)

    @cached_property
    def open_sign(self) -> np.ndarray:
        """(num_envs, J) float64: +1 where opening raises the simulator position, -1 where it lowers it."""
        return self._pad(lambda o: o.open_sign, 1.0, np.float64)

    @cached_property
    def child_parts(self) -> np.ndarray:
        """(num_envs, J) int64 part label each joint moves (k + 1 for joint k), -1 where no joint."""
        return self._pad(lambda o: o.child_parts, -1, np.int64)

    @cached_property
    def target_joint(self) -> np.ndarray:
        """(num_envs,) int64: each sub-scene's target joint slot."""
        return np.array([obj.target_joint for obj in self.objects], dtype=np.int64)

    @cached_property
    def grasp_local(self) -> np.ndarray:
        """(num_envs, 3) float64 grasp point in the grasp link's frame, metres."""
        return np.stack([np.asarray(obj.grasp_local, dtype=np.float64) for obj in self.objects])

    @cached_property
    def aabb(self) -> np.ndarray:
        """(num_envs, 2, 3) float64 object-frame bounds (min, max) at the closed state, metres."""
        return np.array([[obj.aabb[0], obj.aabb[1]] for obj in self.objects], dtype=np.float64)

    @cached_property
    def placement_shift(self) -> np.ndarray:
        """(num_envs, 2) float64 world metres each object is moved from the task's placement (user
        files placed by default: see :func:`capt_env.tasks.object_loading.grasp_reach_shift`)."""
        return np.array([obj.placement_shift for obj in self.objects], dtype=np.float64)

    @cached_property
    def front_yaw(self) -> np.ndarray:
        """(num_envs,) float64 yaw (rad) that turns each object's front towards the robot (-x)."""
        return np.array([obj.front_yaw for obj in self.objects], dtype=np.float64)

    @cached_property
    def segmentation_lut(self) -> torch.Tensor:
        """(num_envs, L) long: sub-scene i's part label of each per-scene segmentation id, -1 for
        ids that are not the object."""
        width = max(int(obj.segmentation_lut.shape[-1]) for obj in self.objects)
        lut = torch.full((self.num_envs, width), -1, dtype=torch.long)
        for i, obj in enumerate(self.objects):
            lut[i, : obj.segmentation_lut.shape[-1]] = obj.segmentation_lut[0]
        return lut.to(self.device)

    def _pad(self, values: Callable[[LoadedObject], Any], fill: float, dtype: type) -> np.ndarray:
        """Stack ``values(obj)`` ((dof, ...) per object) into (num_envs, J, ...), ``fill`` past dof."""
        rows = [np.asarray(values(obj), dtype=dtype) for obj in self.objects]
        tail = max((r.shape[1:] for r in rows), key=len)
        out = np.full((self.num_envs, self.max_dof, *tail), fill, dtype=dtype)
        for i, row in enumerate(rows):
            out[i, : len(row)] = row
        return out

    # ------------------------------------------------------------ torch, on the env's device
    def tensor(self, name: str, dtype: torch.dtype | None = None) -> torch.Tensor:
        """One of the per-sub-scene arrays above as a tensor on the env's device (cached)."""
        key = (name, dtype)
        cache = self._tensors
        if key not in cache:
            cache[key] = torch.as_tensor(getattr(self, name), dtype=dtype, device=self.device)
        return cache[key]

    @cached_property
    def _tensors(self) -> dict[tuple[str, torch.dtype | None], torch.Tensor]:
        return {}

    def sim_qpos(self, state: np.ndarray, rows: np.ndarray) -> np.ndarray:
        """Simulator joint positions (n, J) of task joint states ``state`` (n, J) of sub-scenes
        ``rows`` (n,) (0 closed, growing while opening); 0 in padded slots."""
        mask = self.joint_mask[rows]
        return np.where(mask, self.closed_qpos[rows] + self.open_sign[rows] * np.asarray(state), 0.0)

    def task_state(self, qpos: torch.Tensor) -> torch.Tensor:
        """Task joint states (num_envs, J) of the simulator positions ``qpos`` (num_envs, J) of every
        sub-scene (the inverse of :meth:`sim_qpos`); 0 in padded slots."""
        closed = self.tensor("closed_qpos", qpos.dtype)
        sign = self.tensor("open_sign", qpos.dtype)
        state = sign * (qpos - closed)
        return torch.where(self.tensor("joint_mask"), state, torch.zeros_like(state))

    def target_values(self, per_joint: torch.Tensor) -> torch.Tensor:
        """Each sub-scene's target-joint entry of a (num_envs, J, ...) tensor: (num_envs, ...)."""
        rows = torch.arange(self.num_envs, device=per_joint.device)
        return per_joint[rows, self.tensor("target_joint").to(per_joint.device)]

    def joint_frames(self) -> tuple[torch.Tensor, torch.Tensor]:
        """World-frame joint axes (num_envs, J, 3), unit and turned so that a growing task state
        opens, and pivots (num_envs, J, 3), metres (the joint frame's origin); zeros where no joint."""
        axes = torch.zeros((self.num_envs, self.max_dof, 3), device=self.device)
        pivots = torch.zeros_like(axes)
        sign = self.tensor("open_sign", torch.float32)
        for k, slot in enumerate(self.slots):
            mat = slot.joint.get_global_pose().to_transformation_matrix()  # (n, 4, 4)
            axes[slot.rows, k] = sign[slot.rows, k].unsqueeze(-1) * mat[..., :3, 0]
            pivots[slot.rows, k] = mat[..., :3, 3]
        return axes, pivots

    def grasp_point(self) -> torch.Tensor:
        """(num_envs, 3) world-frame grasp point of every sub-scene, metres."""
        mat = self.grasp_link.pose.to_transformation_matrix()
        local = self.tensor("grasp_local", torch.float32)
        return (mat[..., :3, :3] @ local.unsqueeze(-1)).squeeze(-1) + mat[..., :3, 3]


def _rows(indices: Sequence[int], device: torch.device) -> torch.Tensor:
    return torch.as_tensor(list(indices), dtype=torch.long, device=device)


def shared_batch(obj: LoadedObject, num_envs: int, device: torch.device) -> ObjectBatch:
    """The batch of one object built into all ``num_envs`` sub-scenes."""
    rows = _rows(range(num_envs), device)
    return ObjectBatch(
        objects=(obj,) * num_envs, articulation=obj.articulation,
        slots=tuple(JointSlot(joint, rows) for joint in obj.joints),
        grasp_link=obj.grasp_link, target_link=obj.target_child_link, shared=True, device=device,
    )


def merged_batch(scene: Any, objects: Sequence[LoadedObject], device: torch.device, name: str = "object"
                 ) -> ObjectBatch:
    """The batch of ``objects[i]`` built into sub-scene ``i`` only: one merged articulation view
    ``name`` (it replaces the per-sub-scene ones in the scene's state dict, so env states keep one
    row per sub-scene) and merged link views for the joint slots, grasp links and target links."""
    for obj in objects:
        scene.remove_from_state_dict_registry(obj.articulation)
    art = Articulation.merge([obj.articulation for obj in objects], name=name)
    scene.add_to_state_dict_registry(art)
    slots = []
    for k in range(max(obj.dof for obj in objects)):
        rows = [i for i, obj in enumerate(objects) if k < obj.dof]
        link = Link.merge([objects[i].joints[k].child_link for i in rows], name=f"{name}_joint_{k}_child")
        slots.append(JointSlot(link.joint, _rows(rows, device)))
    return ObjectBatch(
        objects=tuple(objects), articulation=art, slots=tuple(slots),
        grasp_link=Link.merge([obj.grasp_link for obj in objects], name=f"{name}_grasp_link"),
        target_link=Link.merge([obj.target_child_link for obj in objects], name=f"{name}_target_link"),
        shared=False, device=device,
    )


def choose_instances(cfg: TaskConfig, rngs: Sequence[np.random.RandomState],
                     instance_ids: Sequence[int] | None = None) -> list[int]:
    """One procedural instance id per sub-scene: ``instance_ids[i]`` (checked against the allowed
    ids) if given, else sub-scene i's draw from ``rngs[i]`` (its episode RNG, one ``randint``)."""
    wanted: Sequence[int | None] = [None] * len(rngs) if instance_ids is None else instance_ids
    return [choose_instance(cfg, rng, iid) for rng, iid in zip(rngs, wanted, strict=True)]


def load_objects(scene: Any, cfg: TaskConfig, rngs: Sequence[np.random.RandomState],
                 instance_id: InstanceChoice = None) -> ObjectBatch:
    """Build the task's object into every sub-scene of ``scene`` (root at each sub-scene's origin,
    every joint closed) and describe them as a batch; ``rngs[i]`` is sub-scene i's episode RNG.

    Per-sub-scene instances for a procedural category with more than one sub-scene, unless
    ``instance_id`` is one id; else one object in every sub-scene (see the module docstring)."""
    num_envs = int(scene.num_envs)
    device = torch.device(scene.device or "cpu")
    if len(rngs) != num_envs:
        raise ValueError(f"need one RNG per sub-scene: {len(rngs)} for {num_envs}")
    if instance_id is not None and not isinstance(instance_id, (int, np.integer)):
        ids = [int(i) for i in instance_id]
        if len(ids) != num_envs:
            raise ValueError(f"instance_id: {len(ids)} ids for {num_envs} sub-scenes; give one id or one per "
                             "sub-scene")
        instance_id = ids[0] if num_envs == 1 else ids
    if cfg.category is None or num_envs == 1 or isinstance(instance_id, (int, np.integer)):
        return shared_batch(load_object(scene, cfg, rngs[0], instance_id), num_envs, device)
    objects = [load_procedural(scene, cfg, iid, name=f"object-{i}", scene_idxs=[i])
               for i, iid in enumerate(choose_instances(cfg, rngs, instance_id))]
    return merged_batch(scene, objects, device)
