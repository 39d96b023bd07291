"""Convex hulls as Wavefront OBJ files, because SAPIEN's builders read convex meshes from files.

One folder per process (removed at exit); a hull's file is named by a hash of its vertices, so a
shape built again (every reconfiguration of the same instance) reuses its file.
"""

from __future__ import annotations

import atexit
import hashlib
import shutil
import tempfile
from collections.abc import Sequence
from pathlib import Path

import numpy as np
import trimesh

_DIR: Path | None = None


def _folder() -> Path:
    global _DIR
    if _DIR is None:
        _DIR = Path(tempfile.mkdtemp(prefix="capt_meshes_"))
        atexit.register(shutil.rmtree, _DIR, True)
    return _DIR


def convex_hull(vertices: Sequence[Sequence[float]]) -> trimesh.Trimesh:
    """The convex hull of ``vertices`` (V, 3), metres, with outward-facing triangles."""
    return trimesh.convex.convex_hull(np.asarray(vertices, dtype=np.float64))


def convex_mesh_file(vertices: Sequence[Sequence[float]]) -> str:
    """Path of an OBJ file holding the convex hull of ``vertices`` (V, 3), metres."""
    pts = np.asarray(vertices, dtype=np.float64)
    key = hashlib.sha1(np.ascontiguousarray(pts).tobytes()).hexdigest()[:20]
    path = _folder() / f"hull_{key}.obj"
    if not path.exists():
        tmp = path.with_suffix(".tmp.obj")
        convex_hull(pts).export(tmp)
        tmp.replace(path)
    return str(path)
