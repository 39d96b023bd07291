"""A bare ManiSkill scene (CPU PhysX, optional rendering) for building and testing objects outside
of a task: tests, notebooks and quick physics checks. Gravity is PhysX's default (-9.81 m/s^2 on z).
"""

from __future__ import annotations

import dataclasses

import sapien
import sapien.physx as physx
import torch
from mani_skill.envs.scene import ManiSkillScene
from mani_skill.envs.utils.system.backend import parse_sim_and_render_backend
from mani_skill.utils.structs.types import SimConfig


def create_scene(render: bool = False, timestep: float = 0.01) -> ManiSkillScene:
    """One CPU sub-scene wrapped as a ManiSkillScene.

    :param render: also create a render system (needs a Vulkan device, e.g. lavapipe); without it
        links get no visual shapes, which is enough for physics.
    :param timestep: physics step in seconds (ManiSkill tasks use 0.01 s, i.e. 100 Hz).
    """
    backend = parse_sim_and_render_backend("physx_cpu", "none")
    systems: list = [physx.PhysxCpuSystem()]
    if render:
        render_system = sapien.render.RenderSystem()  # SAPIEN's default (first usable) device
        systems.append(render_system)
        backend = dataclasses.replace(backend, render_device=render_system.device)
    scene = ManiSkillScene(
        [sapien.Scene(systems)], sim_config=SimConfig(), device=torch.device("cpu"), backend=backend
    )
    scene.px.timestep = timestep
    return scene
