"""Record what the ``capt`` perception source is given and what it returns, for a replay test.

For each category and seed: one env reset and ``--steps`` zero-action steps with ``source: capt``
(the shipped checkpoint, every step perceived, the wrapper config's defaults otherwise). Per
perception call it stores the isolated object points (``dense``, float32: the renderer's own
precision, so lossless), the indices of the network's input among them, the network's output
(part labels and joints) and the source's final estimate. A test replays the network's outputs
through the source and asserts the same estimates, so the refiners and the fusion can change shape
without changing what a policy sees. World frame, metres, radians.

    .venv/bin/python scripts/record_capt_estimates.py --out tests/data/capt_estimates.npz
"""

from __future__ import annotations

import argparse
from typing import Any

import numpy as np


def record(category: str, seeds: list[int], steps: int) -> list[dict[str, Any]]:
    """One dict per perception call of the ``capt`` source on ``category`` (see the module doc)."""
    from capt_env.env_factory import make_env
    from perception.checkpoints import default_checkpoint

    env = make_env(category, {"source": "capt", "checkpoint": str(default_checkpoint(category))},
                   obs_mode="pointcloud")
    source, calls = env.source, []
    estimate, predict = source.estimate, source.estimator.predict

    def recording_predict(points: np.ndarray) -> Any:
        out = predict(points)
        calls[-1]["network"] = out
        return out

    def recording_estimate(points: np.ndarray, info: dict, dense_points: np.ndarray | None = None,
                           viewpoint: np.ndarray | None = None) -> Any:
        calls.append({"points": np.array(points), "dense": np.array(dense_points),
                      "target": int(np.asarray(info["target_joint"]).reshape(-1)[0]),
                      "viewpoint": np.full(3, np.nan) if viewpoint is None else np.array(viewpoint)})
        calls[-1]["estimate"] = estimate(points, info, dense_points=dense_points, viewpoint=viewpoint)
        return calls[-1]["estimate"]

    source.estimator.predict = recording_predict
    source.estimate = recording_estimate
    try:
        for episode, seed in enumerate(seeds):
            env.reset(seed=seed)
            for _ in range(steps):
                env.step(np.zeros(env.action_space.shape, dtype=np.float32))
            for c in calls:
                c.setdefault("episode", episode)
    finally:
        env.close()
    return calls


def to_arrays(category: str, calls: list[dict[str, Any]]) -> dict[str, np.ndarray]:
    """Flat arrays of the calls of one category, keyed ``<category>/<call>/<field>``."""
    out: dict[str, np.ndarray] = {}
    for i, c in enumerate(calls):
        key = f"{category}/{i}"
        dense = c["dense"]
        same = i > 0 and np.array_equal(calls[i - 1]["dense"], dense)  # a still scene renders alike
        owner = out[f"{category}/{i - 1}/dense_call"] if same else np.array(i)
        rows = {tuple(p): j for j, p in enumerate(dense)}
        idx = np.array([rows[tuple(p)] for p in c["points"]], dtype=np.uint16)
        assert np.array_equal(dense[idx], c["points"])
        assert np.array_equal(dense.astype(np.float32).astype(np.float64), dense)
        net, est = c["network"], c["estimate"]
        if not same:
            out[f"{key}/dense"] = dense.astype(np.float32)
        out |= {f"{key}/dense_call": owner, f"{key}/input": idx,
                f"{key}/episode": np.array(c["episode"]), f"{key}/target": np.array(c["target"]),
                f"{key}/viewpoint": c["viewpoint"],
                f"{key}/labels": np.asarray(net.part_labels, dtype=np.int8),
                f"{key}/joint_types": np.array([j.type for j in net.joints]),
                f"{key}/joint_directions": np.array([j.direction for j in net.joints]),
                f"{key}/joint_pivots": np.array([j.pivot for j in net.joints]),
                f"{key}/joint_states": np.array([j.state for j in net.joints]),
                f"{key}/joint_confidences": np.array([j.confidence for j in net.joints]),
                f"{key}/estimate_type": np.array(est.joint_type),
                f"{key}/estimate": np.concatenate([est.direction, est.pivot, [est.state], est.grasp_point,
                                                   [est.confidence]])}
    return out


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--categories", nargs="+", default=["cabinet_door", "drawer_cabinet", "laptop"])
    parser.add_argument("--seeds", type=int, nargs="+", default=[0, 2], help="development seeds")
    parser.add_argument("--steps", type=int, default=1, help="zero-action steps after each reset")
    parser.add_argument("--out", required=True, help=".npz to write")
    args = parser.parse_args()
    arrays: dict[str, np.ndarray] = {}
    for category in args.categories:
        arrays |= to_arrays(category, record(category, args.seeds, args.steps))
    np.savez_compressed(args.out, **arrays)
    print(f"wrote {args.out}: {len(arrays)} arrays")


if __name__ == "__main__":
    main()
