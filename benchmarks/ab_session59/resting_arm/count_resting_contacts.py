"""Count resets whose first step has the resting arm pressing on the object (a robot-object contact
with an impulse over 1e-4 N s or a penetration), two cameras, oracle, state observations.

    python count_resting_contacts.py CATEGORY FIRST_SEED EPISODES
"""

import sys

import numpy as np
import yaml

import capt_env.shipped_configs as sc
from capt_env.env_factory import make_env


def main() -> None:
    category, first, n = sys.argv[1], int(sys.argv[2]), int(sys.argv[3])
    task = yaml.safe_load(open(sc.resolve_config("tasks", "two_cameras")))
    env = make_env(category, {"source": "oracle"}, task=task, obs_mode="state")
    touching = []
    for seed in range(first, first + n):
        env.reset(seed=seed)
        env.step(np.zeros(7, dtype=np.float32))
        links = set()
        for contact in env.unwrapped.scene.get_contacts():
            b0, b1 = (body.entity.name for body in contact.bodies)
            impulse = sum(float(np.linalg.norm(p.impulse)) for p in contact.points)
            separation = min((float(p.separation) for p in contact.points), default=1.0)
            if ("panda" in b0) != ("panda" in b1) and (impulse > 1e-4 or separation < 0.0):
                links.add(b0 if "panda" in b0 else b1)
        if links:
            touching.append(seed)
    print(category, len(touching), "of", n, "resets with the arm touching the object:", touching)


if __name__ == "__main__":
    main()
