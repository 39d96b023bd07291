"""The axis measured from a part's motion: a line or circle fitted to the path of a point on it
recovers the true axis from constructed paths, refuses paths that do not tell it, and lets the
opener open a drawer whose estimated axis is 10 degrees off."""

from __future__ import annotations

import numpy as np
import pytest

from agents.scripted.config import ScriptedOpenerConfig, with_options
from agents.scripted.geometry import axis_angle_matrix
from agents.scripted.motion_axis import fit_motion_axis
from agents.scripted.opener import ScriptedOpener
from agents.scripted.rollout import run_episode
from capt_env.env_factory import make_env

FIT = {"min_travel": 0.03, "min_angle": 0.4, "max_rms": 0.004, "max_turn": 0.6, "max_ratio": 0.1}


def _tilted(u: np.ndarray, angle: float) -> np.ndarray:
    perp = np.cross(u, [0.0, 0.0, 1.0]) if abs(u[2]) < 0.9 else np.cross(u, [1.0, 0.0, 0.0])
    perp /= np.linalg.norm(perp)
    return np.cos(angle) * u + np.sin(angle) * perp


def test_a_drawers_path_gives_its_direction_signed_like_the_estimate() -> None:
    rng = np.random.default_rng(0)
    true = np.array([-1.0, 0.2, 0.0]) / np.linalg.norm([-1.0, 0.2, 0.0])
    start = np.array([0.3, 0.1, 0.4])
    path = start + np.linspace(0.0, 0.08, 6)[:, None] * true + rng.normal(0, 0.0005, (6, 3))
    estimate = _tilted(true, np.radians(10.0))
    fit = fit_motion_axis(path, estimate, start, revolute=False, **FIT)
    assert fit is not None and np.degrees(np.arccos(fit.direction @ true)) < 1.0
    assert fit.turn == pytest.approx(np.radians(10.0), abs=np.radians(1.0))
    flipped = fit_motion_axis(path, -estimate, start, revolute=False, **FIT)  # the sign is the estimate's
    assert flipped is not None and flipped.direction @ true < -0.99
    assert fit_motion_axis(path[:2], estimate, start, revolute=False, **FIT) is None  # too few points
    short = start + np.linspace(0.0, 0.02, 4)[:, None] * true
    assert fit_motion_axis(short, estimate, start, revolute=False, **FIT) is None  # 3 cm not travelled yet


def test_a_doors_path_gives_its_hinge_line() -> None:
    hinge, axis = np.array([0.4, -0.3, 0.2]), np.array([0.0, 0.0, 1.0])
    arm = np.array([0.0, 0.35, 0.15])  # the handle, 35 cm from the hinge and 15 cm up it
    path = np.array([hinge + axis_angle_matrix(axis, a) @ arm for a in np.linspace(0.0, 0.6, 7)])
    estimate = _tilted(axis, np.radians(8.0))
    fit = fit_motion_axis(path, estimate, hinge + [0.0, 0.02, 0.0], revolute=True, **FIT)
    assert fit is not None and np.degrees(np.arccos(fit.direction @ axis)) < 0.01
    off = fit.pivot - hinge
    assert np.linalg.norm(off - (off @ axis) * axis) < 1e-6  # on the true hinge line
    # fewer points than asked for are refused (the opener asks a hinge for 6: 4 fit anything)
    assert fit_motion_axis(path[:5], estimate, hinge, revolute=True, **FIT, min_points=6) is None
    # an arc of 0.2 rad does not sweep min_angle; one 20 deg farther than max_turn is refused
    assert fit_motion_axis(path[:3], estimate, hinge, revolute=True, **FIT) is None
    assert fit_motion_axis(path, _tilted(axis, 0.8), hinge, revolute=True, **FIT) is None
    # points scattered by about the arc's own bend out of a line: the plane is not told, refused
    noisy = path + np.random.default_rng(1).normal(0, 0.01, path.shape)
    assert fit_motion_axis(noisy, estimate, hinge, revolute=True, **FIT) is None
    slightly = path + np.random.default_rng(1).normal(0, 0.0005, path.shape)  # half a millimetre
    fit = fit_motion_axis(slightly, estimate, hinge, revolute=True, **FIT)
    assert fit is not None and np.degrees(np.arccos(fit.direction @ axis)) < 3.0


def _drawer_episode(**options: object) -> tuple[bool, float, ScriptedOpener]:
    noise = {"model": "fixed_offset", "direction_rad": float(np.radians(10.0)), "pivot_m": 0.0,
             "state": 0.0, "grasp_m": 0.0}
    env = make_env("drawer_cabinet", {"source": "noisy_oracle", "every_k_steps": 5, "noise": noise})
    opener = ScriptedOpener(with_options(ScriptedOpenerConfig(), **options))
    try:
        result = run_episode(env, opener, seed=0, max_steps=140)
    finally:
        env.close()
    return result.success, result.open_fraction, opener


def test_a_drawer_10_degrees_off_opens_once_its_motion_gives_the_axis() -> None:
    # pulled along the estimate, the drawer binds 8 cm out and the slowing hand reads as its end stop
    opened, fraction, _ = _drawer_episode(pull__prismatic__track_fit_travel=0.0)
    assert not opened and fraction < 0.5
    # the line the holding hand follows (on by default) ...
    opened, fraction, opener = _drawer_episode()
    line = opener.ctx.pull.line_fit
    assert opened and fraction > 0.9 and line is not None
    turn = np.degrees(np.arccos(np.clip(line @ opener.ctx.pull.grasp_u, -1.0, 1.0)))
    assert turn == pytest.approx(10.0, abs=2.0)  # the estimate's error, measured by the hand
    # ... or the path of the estimated grasp point (pull.motion_axis)
    opened, fraction, opener = _drawer_episode(pull__prismatic__track_fit_travel=0.0,
                                               pull__motion_axis__enabled=True)
    assert opened and fraction > 0.9
    motion = opener.ctx.axis.motion
    assert motion is not None and motion.turn == pytest.approx(np.radians(10.0), abs=0.01)
