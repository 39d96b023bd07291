"""Axis geometry used throughout CAPT (paper Sec. III-B/C/D): point-to-axis distance Psi_dist, Rodrigues
rotation Psi_Rodrigues, line-to-line distance and angles, and per-point dist/pdir targets.

Pure torch. An axis (line) is a unit direction ``u`` and any point ``q`` on it (the pivot). All
functions broadcast over leading dimensions; lengths are in the frame of the inputs; angles radians.
"""

from __future__ import annotations

import math

import torch

EPS = 1e-9


def normalize(v: torch.Tensor, eps: float = EPS) -> torch.Tensor:
    """Unit vectors along the last dim (a zero vector stays zero)."""
    return v / v.norm(dim=-1, keepdim=True).clamp_min(eps)


def _dot(a: torch.Tensor, b: torch.Tensor) -> torch.Tensor:
    return (a * b).sum(-1)


def closest_point_on_line(p: torch.Tensor, u: torch.Tensor, q: torch.Tensor) -> torch.Tensor:
    """Foot of ``p`` (..., 3) on the line through ``q`` along ``u`` (unit or not)."""
    u = normalize(u)
    return q + _dot(p - q, u).unsqueeze(-1) * u


def point_line_distance(p: torch.Tensor, u: torch.Tensor, q: torch.Tensor) -> torch.Tensor:
    """Psi_dist(p, q, u) = ||((p-q).u) u - (p-q)||, shape (...)."""
    return (closest_point_on_line(p, u, q) - p).norm(dim=-1)


def _any_perpendicular(u: torch.Tensor) -> torch.Tensor:
    """A deterministic unit vector perpendicular to unit ``u`` (crossed with the least-aligned basis axis)."""
    basis = torch.eye(3, dtype=u.dtype, device=u.device)
    idx = u.abs().argmin(dim=-1)
    return normalize(torch.linalg.cross(u, basis[idx], dim=-1))


def axis_targets(
    points: torch.Tensor, u: torch.Tensor, q: torch.Tensor, eps: float = 1e-7
) -> tuple[torch.Tensor, torch.Tensor]:
    """Per-point ground truth: distance (n,) to the axis and unit pdir (n, 3) from the point to its foot.

    ``points`` (..., n, 3); ``u``, ``q`` (..., 3). Points on the axis (distance < eps) get a fixed
    perpendicular of ``u`` as pdir, so pivot = p + dist * pdir still holds.
    """
    u = normalize(u)
    foot = closest_point_on_line(points, u.unsqueeze(-2), q.unsqueeze(-2))
    offset = foot - points
    dist = offset.norm(dim=-1)
    fallback = _any_perpendicular(u).unsqueeze(-2).expand_as(offset)
    pdir = torch.where((dist > eps).unsqueeze(-1), offset / dist.clamp_min(eps).unsqueeze(-1), fallback)
    return dist, pdir


def rotate_about_axis(p: torch.Tensor, u: torch.Tensor, q: torch.Tensor, angle: torch.Tensor | float
                      ) -> torch.Tensor:
    """Rodrigues: rotate points ``p`` (..., 3) by ``angle`` (right hand about unit ``u``) around the line
    through ``q``."""
    u = normalize(u)
    angle = torch.as_tensor(angle, dtype=p.dtype, device=p.device)
    c, s = torch.cos(angle).unsqueeze(-1), torch.sin(angle).unsqueeze(-1)
    v = p - q
    v_rot = v * c + torch.linalg.cross(u.expand_as(v), v, dim=-1) * s + u * _dot(u, v).unsqueeze(-1) * (1 - c)
    return q + v_rot


def translate_along_axis(p: torch.Tensor, u: torch.Tensor, distance: torch.Tensor | float) -> torch.Tensor:
    """Move points ``p`` (..., 3) by ``distance`` along unit ``u`` (a prismatic joint's motion)."""
    distance = torch.as_tensor(distance, dtype=p.dtype, device=p.device)
    return p + normalize(u) * distance.unsqueeze(-1)


def line_line_distance(u1: torch.Tensor, q1: torch.Tensor, u2: torch.Tensor, q2: torch.Tensor,
                       parallel_tol: float = 1e-6) -> torch.Tensor:
    """Shortest distance between two infinite lines (0 when they intersect).

    Skew lines: |(q2-q1).(u1 x u2)| / |u1 x u2|; (nearly) parallel lines (|u1 x u2| < parallel_tol):
    distance from q2 to line 1.
    """
    u1, u2 = normalize(u1), normalize(u2)
    w = q2 - q1
    cross = torch.linalg.cross(u1, u2, dim=-1)
    cn = cross.norm(dim=-1)
    skew = _dot(w, cross).abs() / cn.clamp_min(parallel_tol)
    parallel = point_line_distance(q2, u1, q1)
    return torch.where(cn < parallel_tol, parallel, skew)


def angle_between(a: torch.Tensor, b: torch.Tensor) -> torch.Tensor:
    """Angle in [0, pi] between vectors (signed directions: opposite vectors are pi apart)."""
    a, b = normalize(a), normalize(b)
    # atan2 of |a x b| and a.b is accurate near 0 and pi, unlike acos.
    return torch.atan2(torch.linalg.cross(a, b, dim=-1).norm(dim=-1), _dot(a, b))


def axis_angle_between(a: torch.Tensor, b: torch.Tensor) -> torch.Tensor:
    """Angle in [0, pi/2] between unoriented axes (a and -a are the same axis)."""
    ang = angle_between(a, b)
    return torch.minimum(ang, math.pi - ang)
