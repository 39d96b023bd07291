"""Double voting (paper Sec. III-D): outlier rejection, CAPT-plain mean, window search, confidence."""

from __future__ import annotations

import numpy as np

from perception.metrics import direction_error_deg, line_distance
from perception.voting import PointPredictions, choose_voting_window, vote


def _planted(seed: int = 0, n: int = 500, bad_share: float = 0.2):
    """Points spread 0.05-0.5 from the axis z through (0.1, 0, 0); the 20% nearest the axis predict
    wild directions and pivots, the rest predict the truth with small noise."""
    rng = np.random.default_rng(seed)
    u, q = np.array([0.0, 0.0, 1.0]), np.array([0.1, 0.0, 0.0])
    r = np.sort(rng.uniform(0.05, 0.5, n))
    phi = rng.uniform(-np.pi, np.pi, n)
    pts = q + np.stack([r * np.cos(phi), r * np.sin(phi), rng.uniform(-0.3, 0.3, n)], axis=1)
    foot = q + ((pts - q) @ u)[:, None] * u[None]
    dist = np.linalg.norm(foot - pts, axis=1)
    pdir = (foot - pts) / dist[:, None]
    dirs = u + rng.normal(0, 0.02, (n, 3))
    bad = np.arange(n) < int(bad_share * n)  # the points nearest the axis
    dirs[bad] = rng.normal(size=(bad.sum(), 3)) + np.array([3.0, 0, 0])
    dist = dist + rng.normal(0, 0.002, n)
    dist[bad] += rng.uniform(0.2, 0.4, bad.sum())
    pdir[bad] = np.array([0.0, 1.0, 0.0])  # wild pivots, all pushed one way
    pred = PointPredictions(pts, dirs[:, None], dist[:, None], pdir[:, None], np.full((n, 1), 0.7))
    return pred, u, q


def test_fine_vote_rejects_outliers_near_axis():
    pred, u, q = _planted()
    coarse = vote(pred, [0], 0.75, 2.0, double=False)[0]
    fine = vote(pred, [0], 0.75, 2.0, double=True)[0]
    dir_c, dir_f = direction_error_deg(coarse.direction, u), direction_error_deg(fine.direction, u)
    pos_c = line_distance(coarse.direction, coarse.pivot, u, q)
    pos_f = line_distance(fine.direction, fine.pivot, u, q)
    assert dir_c > 8.0 and dir_f < 1.0
    assert pos_f < 0.01 and pos_f < pos_c / 5
    assert fine.num_voters < coarse.num_voters == 500
    assert fine.confidence > coarse.confidence and 0.0 <= coarse.confidence <= 1.0
    assert abs(fine.state - 0.7) < 1e-9


def test_plain_mean_and_fallback_to_coarse():
    pred, _, _ = _planted()
    coarse = vote(pred, [0], 0.5, 2.0, double=False)[0]
    assert coarse.num_voters == 500
    expected_pivot = (pred.points + pred.dist[:, :1] * pred.pdir[:, 0]).mean(0)
    assert np.allclose(coarse.pivot, expected_pivot)
    empty = vote(pred, [0], 100.0, 200.0, double=True, min_points=8)[0]  # nobody in the window
    assert np.allclose(empty.direction, coarse.direction) and np.allclose(empty.pivot, coarse.pivot)


def test_prismatic_vote_uses_mean_direction_and_child_centroid():
    pred, u, _ = _planted(bad_share=0.0)
    child = np.zeros((len(pred.points), 1), bool)
    child[:10] = True
    pred = PointPredictions(pred.points, pred.dir, pred.dist, pred.pdir, pred.state, child)
    v = vote(pred, [1], 0.5, 2.0)[0]
    assert direction_error_deg(v.direction, u) < 1.0
    assert np.allclose(v.pivot, pred.points[:10].mean(0))


def test_choose_voting_window_prefers_windows_that_drop_the_outliers():
    preds, dirs, pivots, masks = [], [], [], []
    for s in range(3):
        p, u, q = _planted(seed=s)
        preds.append(p)
        dirs.append(u[None])
        pivots.append(q[None])
        masks.append(np.array([True]))
    w0, w1, err = choose_voting_window(preds, dirs, pivots, masks, [0], (0.0, 0.5, 0.75, 1.0),
                                       (1.5, 2.0, 1e9))
    assert w0 >= 0.75  # w0 = 0 would keep the wild points next to the axis
    assert err < 0.5
