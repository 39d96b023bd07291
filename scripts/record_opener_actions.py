"""Record the scripted opener's actions, with ground-truth perception, as the contract a restructured
opener must keep: every observation it saw and every action it took, per episode.

    OMP_NUM_THREADS=1 python scripts/record_opener_actions.py --out tests/data/opener_actions.npz

Episodes: each procedural category on ``--seeds`` (default 300-303) and each object of the Meta-World
corpus (``data/real_objects/corpus.yaml``) on ``--corpus-seeds`` (default 100-102), the opener's
default config, ``--max-steps`` steps or until 10 steps after it is done (as ``capt rollout``).
The archive holds, per episode ``NAME/SEED``, ``obs`` (T, D) the flat observations the opener was
given, ``actions`` (T, 7) float32 what it answered and ``phase_log`` its phase log (JSON);
``tests/agents/test_opener_replay.py`` feeds the observations to the opener of today and replays
whole episodes in the simulator.
"""

from __future__ import annotations

import argparse
import json
import time
from pathlib import Path

import numpy as np

from agents.scripted import ScriptedOpener
from agents.scripted.opener import Phase
from capt_env.commands.object_targets import load_objects_yaml, target_task
from capt_env.env_factory import make_env

CATEGORIES = ("drawer_cabinet", "cabinet_door", "laptop", "oven", "washing_machine")
CORPUS = "data/real_objects/corpus.yaml"


def make_episode_env(name: str, corpus: str = CORPUS):
    """The ground-truth-perception env of procedural category ``name`` or of corpus object ``name``."""
    if name in CATEGORIES:
        return make_env(name, {"source": "oracle"})
    targets = {t.label: t for t in load_objects_yaml(corpus)}
    return make_env(None, {"source": "oracle"}, task=target_task(targets[name], {}))


def corpus_names(corpus: str = CORPUS) -> list[str]:
    """The labels of the corpus objects, in file order."""
    return [t.label for t in load_objects_yaml(corpus)]


def play(env, opener: ScriptedOpener, seed: int, max_steps: int = 200,
         settle_steps: int = 10) -> tuple[np.ndarray, np.ndarray]:
    """One episode: the observations (T, D) given to ``opener`` and its actions (T, 7), ending as
    :func:`agents.scripted.rollout.run_episode` does (``opener.phase_log`` then holds its log)."""
    obs, info = env.reset(seed=seed)
    opener.reset()
    seen, actions, done_for = [], [], 0
    for _ in range(max_steps):
        seen.append(np.array(obs, copy=True))
        action = opener.act(obs, info)
        actions.append(np.asarray(action, dtype=np.float32).copy())
        obs, _, _, truncated, info = env.step(action)
        done_for = done_for + 1 if opener.phase == Phase.DONE else 0
        if done_for >= settle_steps or truncated:
            break
    return np.stack(seen), np.stack(actions)


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--out", default="tests/data/opener_actions.npz")
    parser.add_argument("--seeds", type=int, nargs="+", default=[300, 301, 302, 303])
    parser.add_argument("--corpus-seeds", type=int, nargs="+", default=[100, 101, 102])
    parser.add_argument("--max-steps", type=int, default=200)
    args = parser.parse_args()
    if any(s >= 10000 for s in [*args.seeds, *args.corpus_seeds]):
        raise SystemExit("seeds from 10000 are held out for reporting")
    plan = [(c, args.seeds) for c in CATEGORIES] + [(n, args.corpus_seeds) for n in corpus_names()]
    arrays: dict[str, np.ndarray] = {}
    for name, seeds in plan:
        env = make_episode_env(name)
        for seed in seeds:
            t0 = time.time()
            opener = ScriptedOpener()
            obs, actions = play(env, opener, seed, args.max_steps)
            arrays[f"{name}/{seed}/obs"] = obs
            arrays[f"{name}/{seed}/actions"] = actions
            arrays[f"{name}/{seed}/phase_log"] = np.array(json.dumps(opener.phase_log))
            print(f"{name} {seed}: {len(actions)} steps, {time.time() - t0:.1f} s", flush=True)
        env.close()
    Path(args.out).parent.mkdir(parents=True, exist_ok=True)
    np.savez_compressed(args.out, **arrays)
    print(f"wrote {args.out} ({Path(args.out).stat().st_size / 1e3:.0f} kB)")


if __name__ == "__main__":
    main()
