"""How far the resting-arm rule moves objects (held-out seeds 10000-10049 of a category, or 10000-10009 of
each object of an objects YAML), two cameras, state observations.

    python measure_moves.py CATEGORY | OBJECTS_YAML
"""
import sys, numpy as np, yaml
import capt_env.tasks.open_articulated as oa
from capt_env.env_factory import make_env
import capt_env.shipped_configs as sc
from capt_env.commands.object_targets import load_objects_yaml, target_task
shifts = []
orig = oa.clear_of_resting_arm
def spy(*a):
    r = orig(*a); shifts.append(float(r[0])); return r
oa.clear_of_resting_arm = spy
task = yaml.safe_load(open(sc.resolve_config("tasks", "two_cameras")))
what = sys.argv[1]
if what.endswith(".yaml"):
    for t in load_objects_yaml(what):
        shifts.clear()
        env = make_env(None, {"source": "oracle"}, task=target_task(t, task), obs_mode="state")
        for s in range(10000, 10010): env.reset(seed=s)
        print(t.label, "shift (m) over 10 resets: max %.3f, moved %d" % (max(shifts), sum(x > 0 for x in shifts)))
        env.close()
else:
    env = make_env(what, {"source": "oracle"}, task=task, obs_mode="state")
    for s in range(10000, 10050): env.reset(seed=s)
    sh = shifts[1:]; print(what, "over %d resets: moved %d, median move of those %.3f m, max %.3f m" % (len(sh), sum(x > 0 for x in sh), float(np.median([x for x in sh if x > 0] or [0])), max(sh)))
