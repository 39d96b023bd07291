"""A/B of the planned pre-grasp (tried_planned_approach.diff applied to 52a6e33; needs numpy < 2 for mplib).

    python ab_planned_approach.py OBJECTS_YAML FIRST_SEED EPISODES MODE

One object of OBJECTS_YAML (absolute paths), oracle perception every 5 steps, two cameras,
pointcloud observations. MODE: ``off`` (the straight pre-grasp), ``cloud`` (planned round the
isolated camera cloud), ``gt`` (planned round 20,000 points sampled on the object's collision meshes).
Prints each seed's success, failure cause and the opener's plan checks, then the total.
"""
import sys

import numpy as np
import trimesh
import yaml
from mani_skill.utils.geometry.trimesh_utils import get_component_mesh

import capt_env.shipped_configs as sc
from agents.scripted.config import ScriptedOpenerConfig
from agents.scripted.opener import ScriptedOpener
from agents.scripted.rollout import run_episode
from capt_common.typed_yaml import from_dict
from capt_env.env_factory import make_env
from capt_env.wrappers.perception_wrapper import CaptObservationWrapper


def gt_cloud(self, obs):
    art = self.env.unwrapped.articulation
    meshes = []
    for link in art.get_links():
        m = get_component_mesh(link._objs[0], to_world_frame=True)
        if m is not None:
            meshes.append(m)
    mesh = trimesh.util.concatenate(meshes)
    pts, _ = trimesh.sample.sample_surface_even(mesh, 20000, seed=0)
    self._object_points = len(pts)
    return np.asarray(pts, dtype=np.float32)

if sys.argv[4] == "gt":
    CaptObservationWrapper._object_cloud = gt_cloud
name, first, n = sys.argv[1], int(sys.argv[2]), int(sys.argv[3])
cfg = from_dict(ScriptedOpenerConfig, {"plan": {"enabled": sys.argv[4] != "off"}}, where="x")
objs = yaml.safe_load(open(name))["objects"][0]
task = yaml.safe_load(open(sc.resolve_config("tasks", "two_cameras")))
task = {**task, "object": objs["path"], **(objs.get("task") or {})}
env = make_env(None, {"source": "oracle", "every_k_steps": 5}, task=task, obs_mode="pointcloud")
op = ScriptedOpener(cfg)
wins = 0
for s in range(first, first + n):
    r = run_episode(env, op, s)
    wins += r.success
    print(s, int(r.success), r.cause, op.ctx.plan_checks, flush=True)
print(name, sys.argv[4], wins, "/", n)
