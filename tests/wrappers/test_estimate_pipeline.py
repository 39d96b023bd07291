"""The estimate pipeline on recorded looks: ``capt`` gives what it gave before the pipeline was split
into refiners, and with no refiners it is ``capt_raw``, the network's own estimate.

``tests/data/capt_estimates.npz`` (``scripts/record_capt_estimates.py``, first recorded before the
refactor; re-recorded only when a refiner's output changes on purpose, which the commit says): per
perception call of the ``capt`` source with the shipped checkpoints (cabinet door, drawer cabinet,
laptop; seeds 0 and 2; at reset and one step later), the isolated points, the network's input and
output, and the estimate. The network is replayed, so no rendering and no torch model run here.
"""

from __future__ import annotations

from collections.abc import Iterator
from pathlib import Path
from types import SimpleNamespace
from typing import Any

import numpy as np
import pytest

from capt_common.typed_yaml import from_dict
from capt_env.wrappers.config import PerceptionWrapperConfig
from capt_env.wrappers.estimate import JointAxisEstimate, grasp_point_of_part, unit
from capt_env.wrappers.estimate_pipeline import EstimatePipeline, Look, network
from capt_env.wrappers.perception_sources import CaptSource, make_source
from perception.inference import ArticulationEstimate, JointEstimate

RECORDED = Path(__file__).resolve().parents[1] / "data" / "capt_estimates.npz"
MODELS = {  # the shipped models' joints (perception/checkpoints/<category>.pt), all the refiners read
    "cabinet_door": SimpleNamespace(joint_child_parts=(1,), joint_types=("revolute",)),
    "drawer_cabinet": SimpleNamespace(joint_child_parts=(1, 2, 3), joint_types=("prismatic",) * 3),
    "laptop": SimpleNamespace(joint_child_parts=(1,), joint_types=("revolute",)),
}


def _calls(category: str) -> Iterator[tuple[int, Look, np.ndarray]]:
    """(episode, look, recorded estimate [direction, pivot, state, grasp, confidence]) per call."""
    z = np.load(RECORDED)
    n = len({k.split("/")[1] for k in z.files if k.startswith(f"{category}/")})
    for i in range(n):
        def get(name: str, i: int = i) -> np.ndarray:
            return z[f"{category}/{i}/{name}"]

        dense = z[f"{category}/{int(get('dense_call'))}/dense"].astype(np.float64)
        joints = tuple(JointEstimate(k, str(t), d, p, float(s), float(c)) for k, (t, d, p, s, c) in enumerate(
            zip(get("joint_types"), get("joint_directions"), get("joint_pivots"), get("joint_states"),
                get("joint_confidences"), strict=True)))
        result = ArticulationEstimate(get("labels").astype(np.int64), joints, 0.0)
        points = dense[get("input").astype(np.int64)]
        viewpoint = get("viewpoint").astype(np.float64) if f"{category}/{i}/viewpoint" in z.files else None
        if viewpoint is not None and np.isnan(viewpoint).any():
            viewpoint = None
        seen = Look(points, dense, int(get("target")), result, MODELS[category], viewpoint)
        yield int(get("episode")), seen, get("estimate")


def _source(config: dict[str, Any]) -> CaptSource:
    source = make_source(from_dict(PerceptionWrapperConfig, {"checkpoint": "unused.pt", **config}))
    assert isinstance(source, CaptSource)
    return source


def _replay(source: CaptSource, category: str) -> Iterator[tuple[int, Look, JointAxisEstimate, np.ndarray]]:
    """The source's estimate of every recorded call, its network replayed, episodes reset as recorded."""
    episode = -1
    for ep, seen, recorded in _calls(category):
        if ep != episode:
            episode = ep
            source.reset()
        source._estimator = SimpleNamespace(predict=lambda _p, r=seen.result: r,
                                            config=SimpleNamespace(model=seen.model))
        est = source.estimate(seen.points, {"target_joint": np.array([seen.target])},
                              dense_points=seen.dense_points, viewpoint=seen.viewpoint)
        yield ep, seen, est, recorded


def _flat(est: JointAxisEstimate) -> np.ndarray:
    return np.concatenate([est.direction, est.pivot, [est.state], est.grasp_point, [est.confidence]])


@pytest.mark.parametrize("category", sorted(MODELS))
def test_capt_gives_the_estimates_recorded_before_the_refactor(category: str) -> None:
    calls = list(_replay(_source({"source": "capt"}), category))
    assert len(calls) == 4
    for _, _, est, recorded in calls:
        np.testing.assert_allclose(_flat(est), recorded, rtol=0.0, atol=1e-12)


@pytest.mark.parametrize("category", sorted(MODELS))
def test_no_refiners_is_capt_raw_the_networks_own_estimate(category: str) -> None:
    raw = list(_replay(_source({"source": "capt_raw"}), category))
    bare = list(_replay(_source({"source": "capt", "refiners": []}), category))
    first_looks = 0
    for (ep, seen, est, _), (_, _, fused, _), previous in zip(raw, bare, [None, *raw[:-1]], strict=True):
        same = EstimatePipeline((), None).estimate(seen)
        np.testing.assert_array_equal(_flat(est), _flat(same))
        joint = seen.result.joints[seen.target]
        np.testing.assert_array_equal(est.direction, unit(joint.direction))
        assert est.state == joint.state and est.confidence == joint.confidence
        assert np.linalg.norm(np.cross(est.pivot - joint.pivot, est.direction)) < 1e-12  # on its line
        np.testing.assert_array_equal(est.grasp_point, grasp_point_of_part(network(seen).moving, joint.type,
                                                                           est.direction, joint.pivot))
        if previous is None or previous[0] != ep:  # an episode's first look: fusing one look is that look
            first_looks += 1
            np.testing.assert_allclose(_flat(fused), _flat(est), rtol=0.0, atol=1e-12)
    assert first_looks == 2


def test_the_refined_draft_names_the_refiners_that_fired() -> None:
    source = _source({"source": "capt"})
    fired = [source.pipeline.last_draft.fired for _ in _replay(source, "drawer_cabinet")
             if source.pipeline.last_draft is not None]
    assert all("front_normal" in f and "opening_sign" not in f for f in fired)  # the normal opens it
    assert all(f == sorted(f, key=list(PerceptionWrapperConfig().refiners).index) for f in fired)


def test_the_wrapper_observes_capt_raw_on_a_rendered_scene() -> None:
    """End to end (64-pixel cameras): the wrapper's ``capt_raw`` observation holds the network's own
    estimate of its look, and the refined pipeline on that same look differs only by its refiners."""
    from capt_env.env_factory import make_env
    from capt_env.wrappers.joint_observation import decode_observation
    from capt_env.wrappers.refiners import build_refiners

    checkpoint = Path(__file__).resolve().parents[2] / "perception" / "checkpoints" / "cabinet_door.pt"
    env = make_env("cabinet_door", {"source": "capt_raw", "checkpoint": str(checkpoint)},
                   obs_mode="pointcloud", task={"cameras": [{"width": 64, "height": 64}]})
    try:
        obs, _ = env.reset(seed=1)
        assert env.source.name == "capt_raw" and env.source.last_look is not None
        _, observed = decode_observation(obs)
        own = EstimatePipeline((), None).estimate(env.source.last_look)
        np.testing.assert_allclose(observed.direction, own.direction, atol=1e-6)  # float32 observation
        np.testing.assert_allclose(observed.grasp_point, own.grasp_point, atol=1e-6)
        refined = EstimatePipeline(build_refiners(), None)
        refined.estimate(env.source.last_look)
        assert refined.last_draft is not None and refined.last_draft.fired  # something to refine
    finally:
        env.close()


def test_a_target_slot_the_network_found_absent_takes_its_most_confident_joint():
    from capt_env.wrappers.refiners.draft import network_draft
    from perception.inference import ArticulationEstimate, JointEstimate

    pts = np.random.default_rng(0).uniform(-0.2, 0.2, size=(50, 3))
    found = [JointEstimate(1, "prismatic", np.array([0.0, -1.0, 0.0]), np.zeros(3), 0.1, 0.6),
             JointEstimate(2, "prismatic", np.array([0.0, -1.0, 0.0]), np.zeros(3), 0.2, 0.9)]
    result = ArticulationEstimate(np.zeros(50, np.int64), tuple(found), 1.0)
    draft = network_draft(result, pts, target=0, model=None)
    assert draft.target == 2 and draft.state == 0.2
    assert network_draft(result, pts, target=1, model=None).target == 1
