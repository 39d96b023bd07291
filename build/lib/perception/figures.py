"""Figures for the paper's qualitative results: cloud coloured by part, predicted axes red, true green."""

from __future__ import annotations

from collections.abc import Sequence
from pathlib import Path

import numpy as np

PART_COLOURS = np.array([
    [0.55, 0.55, 0.60], [0.20, 0.45, 0.85], [0.95, 0.60, 0.10], [0.30, 0.70, 0.35],
    [0.65, 0.35, 0.75], [0.10, 0.70, 0.75], [0.85, 0.80, 0.20], [0.50, 0.30, 0.20],
])


def plot_cloud_with_axes(
    path: str | Path,
    points: np.ndarray,
    part_labels: np.ndarray,
    predicted_axes: Sequence[tuple[np.ndarray, np.ndarray]] = (),
    true_axes: Sequence[tuple[np.ndarray, np.ndarray]] = (),
    title: str = "",
    axis_length: float | None = None,
) -> Path:
    """Save a PNG of ``points`` (N, 3) coloured by ``part_labels`` (N,), with axis lines.

    Each axis is ``(direction (3,), pivot (3,))`` in the same frame as ``points`` (metres). The line
    is drawn through the pivot, ``axis_length`` long (default: the cloud's bounding-box diagonal),
    predicted axes in red and true axes in green, each with an arrowhead at its + end.
    """
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    points = np.asarray(points, dtype=np.float64)
    labels = np.asarray(part_labels).astype(int)
    if points.ndim != 2 or points.shape[1] != 3 or len(points) != len(labels):
        raise ValueError(f"need points (N, 3) and labels (N,), got {points.shape} and {labels.shape}")
    length = axis_length or float(np.linalg.norm(points.max(0) - points.min(0))) or 1.0
    fig = plt.figure(figsize=(6, 6))
    ax = fig.add_subplot(projection="3d")
    colours = PART_COLOURS[np.mod(np.maximum(labels, 0), len(PART_COLOURS))]
    colours[labels < 0] = (0.85, 0.85, 0.85)
    ax.scatter(points[:, 0], points[:, 1], points[:, 2], c=colours, s=2, depthshade=False)
    for axes, colour in ((true_axes, "green"), (predicted_axes, "red")):
        for direction, pivot in axes:
            d = np.asarray(direction, dtype=np.float64)
            d = d / (np.linalg.norm(d) or 1.0)
            p = np.asarray(pivot, dtype=np.float64)
            a, b = p - 0.5 * length * d, p + 0.5 * length * d
            ax.plot(*zip(a, b, strict=True), color=colour, linewidth=2.5)
            ax.quiver(*b, *(0.15 * length * d), color=colour, linewidth=2.5)
    centre = (points.max(0) + points.min(0)) / 2
    half = 0.6 * length
    ax.set_xlim(centre[0] - half, centre[0] + half)
    ax.set_ylim(centre[1] - half, centre[1] + half)
    ax.set_zlim(centre[2] - half, centre[2] + half)
    ax.set_xlabel("x [m]")
    ax.set_ylabel("y [m]")
    ax.set_zlabel("z [m]")
    ax.set_title(title + "\n(red: predicted axis, green: true axis)", fontsize=9)
    path = Path(path)
    path.parent.mkdir(parents=True, exist_ok=True)
    fig.savefig(path, dpi=110, bbox_inches="tight")
    plt.close(fig)
    return path
