"""Count resets whose first step has the resting arm pressing on the object (a robot-object contact
with an impulse over 1e-4 N s or a penetration), two cameras, oracle, state observations.

    python count_resting_contacts.py CATEGORY FIRST_SEED EPISODES
"""
import sys, numpy as np, gymnasium as gym
from capt_env.env_factory import make_env
import yaml, capt_env.shipped_configs as sc
cat = sys.argv[1]; first = int(sys.argv[2]); n = int(sys.argv[3])
task = yaml.safe_load(open(sc.resolve_config("tasks", "two_cameras")))
env = make_env(cat, {"source": "oracle"}, task=task, obs_mode="state")
touch = []
for s in range(first, first + n):
    obs, info = env.reset(seed=s)
    obs, *_ , info = env.step(np.zeros(7, dtype=np.float32))
    scene = env.unwrapped.scene
    cs = scene.get_contacts()
    links = set()
    for c in cs:
        b0, b1 = c.bodies[0].entity.name, c.bodies[1].entity.name
        imp = sum(float(np.linalg.norm(pt.impulse)) for pt in c.points)
        sep = min((float(pt.separation) for pt in c.points), default=1.0)
        if ("panda" in b0) != ("panda" in b1) and (imp > 1e-4 or sep < 0.0):
            links.add(b0 if "panda" in b0 else b1)
    if links:
        touch.append((s, sorted(links)))
print(cat, len(touch), "of", n, "resets with the arm touching the object:", [t[0] for t in touch])
