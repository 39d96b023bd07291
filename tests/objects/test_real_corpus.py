"""The real-file corpus (Meta-World 3.1.1's object files, laid out by scripts/real_objects.py): every
file loads as shipped, resets closed and steps; its meshes sit on its collision geometry."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

from capt_env.commands.object_targets import load_objects_yaml

CORPUS = Path(__file__).resolve().parents[2] / "data" / "real_objects" / "corpus.yaml"
pytestmark = pytest.mark.skipif(
    not CORPUS.is_file(),
    reason="real-file corpus missing: run `python scripts/real_objects.py data/real_objects` "
           "(scripts/test.sh does; it needs the package registry)",
)
TARGETS = load_objects_yaml(CORPUS) if CORPUS.is_file() else []


def _collision_bounds(link) -> tuple[np.ndarray, np.ndarray] | None:
    from capt_env.objects.link_geometry import collision_shape_meshes

    meshes = collision_shape_meshes(link)
    if not meshes:
        return None
    verts = np.concatenate([m.vertices for m in meshes])
    return verts.min(axis=0), verts.max(axis=0)


@pytest.mark.parametrize("target", TARGETS, ids=[t.label for t in TARGETS])
def test_corpus_file_loads_resets_closed_and_steps(target) -> None:
    from capt_env.objects.link_geometry import link_vertices
    from capt_env.tasks.open_articulated import OpenArticulatedEnv

    env = OpenArticulatedEnv(task=dict(target.task), obs_mode="state")
    try:
        _, info = env.reset(seed=0)
        assert 0.0 <= float(info["open_fraction"][0]) <= 0.06  # closed (up to the reset's 5%)
        for _ in range(3):
            _, _, _, _, info = env.step(np.zeros(env.action_space.shape, dtype=np.float32))
        assert np.isfinite(info["grasp_point"].numpy()).all()
        assert env.object.grasp_source in ("name", "geometry", "edge")
        # drawn meshes and collision primitives of every moving link agree (frames, mesh paths,
        # geom groups converted right): their bounds differ by less than 2 cm on every side
        for joint in env.object.joints:
            link = joint.child_link
            bounds = _collision_bounds(link)
            verts = link_vertices(link)
            if bounds is None or len(verts) == 0:
                continue
            assert np.abs(verts.min(axis=0) - bounds[0]).max() < 0.02, link.name
            assert np.abs(verts.max(axis=0) - bounds[1]).max() < 0.02, link.name
    finally:
        env.close()


def test_corpus_lists_the_issue_s_objects() -> None:
    labels = {t.label for t in TARGETS}
    assert {"mw_drawer", "mw_laptop", "mw_door", "mw_window"} <= labels
