"""``capt bench``: speed on this machine in one run: env steps/s per obs mode and reset time, env + CAPT
every K steps on both rendering paths, CAPT ms per cloud and batched clouds/s on the env's own clouds."""

from __future__ import annotations

import argparse
import statistics
import time
from typing import Any

import numpy as np
from tqdm import tqdm

from capt_common.json_report import write_json


def add_arguments(parser: argparse.ArgumentParser) -> None:
    parser.add_argument("--category", default="laptop", help="object category")
    parser.add_argument("--steps", type=int, default=200, help="random-action steps per obs mode")
    parser.add_argument("--resets", type=int, default=5, help="resets (each builds a new object)")
    parser.add_argument("--obs-modes", nargs="+", default=["state", "pointcloud"], help="obs modes to time")
    parser.add_argument("--width", type=int, default=128, help="camera width and height in pixels")
    parser.add_argument("--first-seed", type=int, default=0, help="episode seed")
    parser.add_argument("--capt-every-k", type=int, nargs="*", default=[1, 5],
                        help="also time env + CAPT perception (shipped checkpoint), run every K steps "
                             "(none: skip CAPT)")
    parser.add_argument("--capt-clouds", type=int, default=100,
                        help="time CAPT alone on at least this many calls over the clouds the env "
                             "runs gave it (0: skip)")
    parser.add_argument("--batch-size", type=int, default=16, help="clouds per predict_batch call")


def measure(category: str, obs_mode: str, steps: int, resets: int, width: int, seed: int) -> dict:
    """Median reset time (s) and steady-state steps/s of one obs mode; the first reset is reported apart."""
    import gymnasium as gym

    import capt_env  # noqa: F401

    task = {"cameras": [{"width": width, "height": width}]}
    t0 = time.perf_counter()
    env = gym.make(capt_env.env_id(category), obs_mode=obs_mode, task=task)
    env.reset(seed=seed)
    first = time.perf_counter() - t0
    times = []
    for i in range(resets):
        t = time.perf_counter()
        env.reset(seed=seed + 1 + i)
        times.append(time.perf_counter() - t)
    env.action_space.seed(seed)
    for _ in range(5):  # warm-up
        env.step(env.action_space.sample())
    t = time.perf_counter()
    for _ in tqdm(range(steps), desc=f"{obs_mode} steps", leave=False):
        _, _, terminated, truncated, _ = env.step(env.action_space.sample())
        if terminated or truncated:
            env.reset()
    elapsed = time.perf_counter() - t
    env.close()
    return {
        "obs_mode": obs_mode,
        "steps_per_second": steps / elapsed,
        "ms_per_step": 1000 * elapsed / steps,
        "reset_seconds_median": statistics.median(times),
        "first_make_and_reset_seconds": first,
    }


def measure_with_capt(category: str, every_k: int, steps: int, width: int, seed: int,
                      render_every_step: bool = False, clouds: list[np.ndarray] | None = None) -> dict:
    """Steps/s of the pointcloud env wrapped with CAPT perception run every ``every_k`` steps. The
    wrapper renders only on perception steps; ``render_every_step`` times the path it replaced (the
    cameras rendered on every step), for an A/B in one run. The object clouds CAPT was given (world
    frame, metres) are appended to ``clouds``."""
    clouds = [] if clouds is None else clouds
    from capt_env.env_factory import make_env
    from perception.checkpoints import default_checkpoint

    wrapper = {"source": "capt", "checkpoint": str(default_checkpoint(category)), "every_k_steps": every_k}
    env = make_env(category, wrapper, obs_mode="pointcloud",
                   task={"cameras": [{"width": width, "height": width}]})
    estimator = env.source.estimator
    predict = estimator.predict

    def recording_predict(points: np.ndarray) -> Any:
        clouds.append(np.array(points))
        return predict(points)

    estimator.predict = recording_predict
    if render_every_step:
        base = env.unwrapped
        base.get_obs = lambda info=None, unflattened=False: base._rendered_obs(info, unflattened)
    env.reset(seed=seed)
    env.action_space.seed(seed)
    latencies = []
    t = time.perf_counter()
    for _ in tqdm(range(steps), desc=f"capt every {every_k}", leave=False):
        _, _, terminated, truncated, info = env.step(env.action_space.sample())
        if info.get("perception_ran"):
            latencies.append(float(env.last_perception_latency_ms))
        if terminated or truncated:
            env.reset()
    elapsed = time.perf_counter() - t
    env.close()
    return {"obs_mode": "pointcloud+capt", "every_k_steps": every_k, "render_every_step": render_every_step,
            "steps_per_second": steps / elapsed,
            "ms_per_step": 1000 * elapsed / steps,
            "perception_ms_median": statistics.median(latencies) if latencies else None}


def measure_capt_alone(category: str, clouds: list[np.ndarray], calls: int, batch_size: int) -> dict:
    """CAPT on the env's own object clouds: median ms per ``predict`` call over at least ``calls``
    calls (cycling over ``clouds``), and clouds/s through ``predict_batch`` in batches of
    ``batch_size``, with the estimator's default thread setting."""
    from perception.checkpoints import default_checkpoint
    from perception.inference import ArticulationEstimator

    est = ArticulationEstimator.from_checkpoint(default_checkpoint(category))
    for c in clouds[:3]:  # warm-up
        est.predict(c)
    times = []
    for i in tqdm(range(max(calls, len(clouds))), desc="capt per cloud", leave=False):
        t = time.perf_counter()
        est.predict(clouds[i % len(clouds)])
        times.append(1000 * (time.perf_counter() - t))
    batches = [clouds[i:i + batch_size] for i in range(0, len(clouds), batch_size)]
    t = time.perf_counter()
    for batch in batches:
        est.predict_batch(batch)
    batched = len(clouds) / (time.perf_counter() - t)
    return {"capt_calls": len(times), "capt_ms_per_cloud_median": statistics.median(times),
            "capt_points_per_cloud_median": float(np.median([len(c) for c in clouds])),
            "batch_size": batch_size, "batched_clouds_per_second": batched,
            "single_clouds_per_second": 1000 / statistics.mean(times)}


def run(args: argparse.Namespace) -> int:
    results = []
    for mode in args.obs_modes:
        r = measure(args.category, mode, args.steps, args.resets, args.width, args.first_seed)
        results.append(r)
        print(f"{args.category:<15} {mode:<11} {r['steps_per_second']:7.1f} steps/s "
              f"({r['ms_per_step']:.1f} ms/step)  reset {r['reset_seconds_median']:.2f} s "
              f"(first make+reset {r['first_make_and_reset_seconds']:.1f} s)")
    state = next((r["steps_per_second"] for r in results if r["obs_mode"] == "state"), None)
    clouds: list[np.ndarray] = []
    for k in args.capt_every_k:
        for every_step in (True, False):  # the old path (render every step), then the wrapper's
            r = measure_with_capt(args.category, k, args.steps, args.width, args.first_seed, every_step,
                                  clouds)
            if state:
                r["ratio_to_state"] = r["steps_per_second"] / state
            results.append(r)
            path = "rendering every step" if every_step else "rendering on perception steps"
            ratio = f", {r['ratio_to_state']:.2f} x state" if state else ""
            print(f"{args.category:<15} pointcloud + CAPT every {k} steps, {path}: "
                  f"{r['steps_per_second']:6.1f} steps/s ({r['ms_per_step']:.1f} ms/step, "
                  f"perception {r['perception_ms_median']:.1f} ms{ratio})")
    capt = None
    if args.capt_clouds > 0 and clouds:
        capt = measure_capt_alone(args.category, clouds, args.capt_clouds, args.batch_size)
        print(f"{args.category:<15} CAPT alone: {capt['capt_ms_per_cloud_median']:.1f} ms per cloud "
              f"(median of {capt['capt_calls']} calls, {capt['capt_points_per_cloud_median']:.0f} "
              f"points); batches of {capt['batch_size']}: {capt['batched_clouds_per_second']:.0f} "
              f"clouds/s (one at a time: {capt['single_clouds_per_second']:.0f})")
    write_json(args.json, {"category": args.category, "camera_pixels": args.width**2, "results": results,
                           "capt_alone": capt})
    return 0
