"""Physics sanity of procedural objects: a part must neither move by itself nor stick.

``probe`` puts the target joint at a fraction of its range in a fresh CPU scene (base fixed,
gravity on) and reports how far it moves in a given time, idle and under a constant opening
effort (2 N m or 10 N on the joint). ``python -m capt_env.objects.physics_check`` prints a table.
"""

from __future__ import annotations

import numpy as np
import sapien
import torch

from capt_env.objects.builder import build_articulated_object
from capt_env.objects.registry import make_object
from capt_env.objects.scene import create_scene
from capt_env.objects.style import GeometryVariation

OPEN_TORQUE = 2.0  # N m, revolute
OPEN_FORCE = 10.0  # N, prismatic


def probe(
    category: str, instance_id: int, seconds: float = 1.0, start_fraction: float = 0.3,
    variation: GeometryVariation | None = None,
) -> dict[str, float]:
    """Fractions of the target joint's range moved in ``seconds`` from ``start_fraction`` of it:
    ``idle`` under gravity alone, ``pushed`` with a constant opening torque/force on the joint.
    ``variation`` varies the instance's geometry (``capt_env.objects.style``)."""
    scene = create_scene(render=False)
    spec = make_object(category, instance_id, variation)
    k = spec.joint_index(spec.target_joint)
    joint = spec.joints[k]
    lo, hi = joint.limits
    effort = OPEN_TORQUE if joint.type == "revolute" else OPEN_FORCE
    arts = [
        build_articulated_object(scene, spec, name=f"o{i}", pose=sapien.Pose([0.0, 2.0 * i, 0.0]))
        for i in range(2)
    ]
    q0 = torch.zeros((1, len(spec.joints)))
    q0[0, k] = lo + start_fraction * (hi - lo)
    for art in arts:
        art.set_qpos(q0)
        art.set_qvel(torch.zeros_like(q0))
    qf = torch.zeros_like(q0)
    qf[0, k] = effort
    for _ in range(int(round(seconds / scene.timestep))):
        arts[1].set_qf(qf)
        scene.px.step()
    moved = [float(art.qpos[0, k] - q0[0, k]) / (hi - lo) for art in arts]
    return {"idle": moved[0], "pushed": moved[1]}


if __name__ == "__main__":
    from capt_env.objects.registry import CATEGORIES

    for cat in CATEGORIES:
        rows = [probe(cat, i) for i in range(0, 1000, 50)]
        idle = np.array([r["idle"] for r in rows])
        pushed = np.array([r["pushed"] for r in rows])
        print(
            f"{cat:16s} idle |max| {np.abs(idle).max():.4f} mean {idle.mean():+.4f}   "
            f"pushed min {pushed.min():.3f} mean {pushed.mean():.3f}"
        )
