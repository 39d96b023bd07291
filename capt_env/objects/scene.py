"""A bare ManiSkill scene (CPU PhysX, one or more sub-scenes, optional rendering) for building and
testing objects outside of a task: tests, notebooks and quick physics checks. Gravity is PhysX's
default (-9.81 m/s^2 on z).
"""

from __future__ import annotations

import dataclasses

import sapien
import sapien.physx as physx
import torch
from mani_skill.envs.scene import ManiSkillScene
from mani_skill.envs.utils.system.backend import parse_sim_and_render_backend
from mani_skill.utils.structs.types import SimConfig


def create_scene(render: bool = False, timestep: float = 0.01, num_scenes: int = 1) -> ManiSkillScene:
    """CPU sub-scenes wrapped as a ManiSkillScene.

    :param render: also create a render system (needs a Vulkan device, e.g. lavapipe; one
        sub-scene only); without it links get no visual shapes, which is enough for physics.
    :param timestep: physics step in seconds (ManiSkill tasks use 0.01 s, i.e. 100 Hz).
    :param num_scenes: sub-scenes, each with its own CPU physics system: enough to build different
        objects per sub-scene (``set_scene_idxs``) and read their links' poses, as the batched
        (GPU) task does; ManiSkill's CPU views read only the first sub-scene's joint positions and
        link velocities, and only the first sub-scene is stepped.
    """
    if num_scenes < 1 or (render and num_scenes > 1):
        raise ValueError(f"num_scenes must be >= 1, and 1 with render; got {num_scenes}")
    backend = parse_sim_and_render_backend("physx_cpu", "none")
    systems: list = [physx.PhysxCpuSystem()]
    if render:
        render_system = sapien.render.RenderSystem()  # SAPIEN's default (first usable) device
        systems.append(render_system)
        backend = dataclasses.replace(backend, render_device=render_system.device)
    sub_scenes = [sapien.Scene(systems)]
    sub_scenes += [sapien.Scene([physx.PhysxCpuSystem()]) for _ in range(num_scenes - 1)]
    scene = ManiSkillScene(sub_scenes, sim_config=SimConfig(), device=torch.device("cpu"), backend=backend)
    scene.px.timestep = timestep
    return scene
