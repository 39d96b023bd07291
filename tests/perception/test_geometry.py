"""Axis geometry: distances, Rodrigues rotation, line-line distance, angles, per-point targets."""

from __future__ import annotations

import math

import numpy as np
import pytest
import torch

from perception.geometry import (
    angle_between,
    axis_angle_between,
    axis_targets,
    closest_point_on_line,
    line_line_distance,
    point_line_distance,
    rotate_about_axis,
    translate_along_axis,
)

T = torch.float64


def t(x):
    return torch.tensor(x, dtype=T)


def test_point_line_distance_and_foot():
    u, q = t([0, 0, 2.0]), t([1.0, 1.0, 5.0])
    p = t([4.0, 5.0, -3.0])
    assert float(point_line_distance(p, u, q)) == pytest.approx(5.0)
    assert torch.allclose(closest_point_on_line(p, u, q), t([1.0, 1.0, -3.0]))


def test_rodrigues_quarter_turn_about_offset_axis():
    u, q = t([0, 0, 1.0]), t([1.0, 0, 0])
    p = t([[2.0, 0, 0.5], [1.0, 0, 3.0]])
    out = rotate_about_axis(p, u, q, math.pi / 2)
    assert torch.allclose(out, t([[1.0, 1.0, 0.5], [1.0, 0, 3.0]]), atol=1e-12)
    # Rotation keeps the distance to the axis.
    assert torch.allclose(point_line_distance(out, u, q), point_line_distance(p, u, q))


def test_translate_along_axis():
    out = translate_along_axis(t([[0.0, 0, 0]]), t([0, 3.0, 0]), 0.5)
    assert torch.allclose(out, t([[0.0, 0.5, 0]]))


@pytest.mark.parametrize(
    ("u1", "q1", "u2", "q2", "expected"),
    [
        ([1, 0, 0], [0, 0, 0], [1, 0, 0], [5, 0, 2], 2.0),  # parallel: perpendicular separation
        ([1, 0, 0], [0, 0, 0], [-1, 0, 0], [0, 3, 4], 5.0),  # anti-parallel
        ([1, 0, 0], [0, 0, 0], [0, 1, 0], [7, -2, 3], 3.0),  # skew, known distance 3
        ([1, 0, 0], [0, 0, 0], [1, 1, 0], [2, 2, 0], 0.0),  # intersecting at the origin
        ([0, 0, 1], [1, 1, 1], [0, 0, 1], [1, 1, -4], 0.0),  # identical lines
    ],
)
def test_line_line_distance(u1, q1, u2, q2, expected):
    d = line_line_distance(t(u1), t(q1), t(u2), t(q2))
    assert float(d) == pytest.approx(expected, abs=1e-9)


def test_angles_signed_and_unsigned():
    a = t([1.0, 0, 0])
    assert float(angle_between(a, -a)) == pytest.approx(math.pi)
    assert float(angle_between(a, t([1.0, 1.0, 0]))) == pytest.approx(math.pi / 4)
    assert float(axis_angle_between(a, -a)) == pytest.approx(0.0, abs=1e-12)
    assert float(axis_angle_between(a, t([-1.0, 1.0, 0]))) == pytest.approx(math.pi / 4)
    # Accurate for tiny angles (acos would lose them).
    assert float(angle_between(a, t([1.0, 1e-7, 0]))) == pytest.approx(1e-7, rel=1e-6)


def test_axis_targets_reconstruct_pivots_and_handle_on_axis_points():
    rng = np.random.default_rng(0)
    u = t(rng.normal(size=3))
    q = t(rng.normal(size=3))
    pts = t(rng.normal(size=(50, 3)))
    pts[0] = q + 0.3 * u  # exactly on the axis
    dist, pdir = axis_targets(pts, u, q)
    assert dist.shape == (50,) and pdir.shape == (50, 3)
    assert torch.allclose(pdir.norm(dim=-1), torch.ones(50, dtype=T))
    feet = pts + dist[:, None] * pdir
    assert torch.allclose(point_line_distance(feet, u, q), torch.zeros(50, dtype=T), atol=1e-9)
    assert torch.allclose(dist, point_line_distance(pts, u, q))
    assert float(dist[0]) < 1e-9
    assert abs(float(pdir[0] @ (u / u.norm()))) < 1e-9  # perpendicular fallback
