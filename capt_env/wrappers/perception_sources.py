"""Where joint estimates come from: ground truth (oracle), ground truth plus noise, or CAPT.

Every source maps (object points, env info) to a world-frame :class:`JointAxisEstimate` of the target
joint. Only :class:`CaptSource` needs the points; it imports ``perception.inference`` lazily, on the
first estimate, so the oracle sources work without torch models or checkpoints.
"""

from __future__ import annotations

from typing import Any, Protocol

import numpy as np

from capt_env.wrappers.config import NoiseConfig
from capt_env.wrappers.estimate import (
    JOINT_TYPES,
    JointAxisEstimate,
    away_from_joint,
    canonical_pivot,
    grasp_point_of_part,
    unit,
)
from capt_env.wrappers.estimate_fusion import EstimateFusion
from capt_env.wrappers.moving_part_geometry import (
    PartPlane,
    coplanar_panel,
    edge_aligned_direction,
    handle_point,
    hinge_on_edge,
    opening_direction,
    part_plane,
)
from capt_env.wrappers.stacked_parts import kth_handle_from_bottom

_MIN_HANDLE_POINTS = 3  # of the model's input cloud: fewer are noise, not a handle


def handle_search_points(points: np.ndarray, dense_points: np.ndarray | None) -> tuple[np.ndarray, int]:
    """(points to look for handles among, the fewest points of a handle): ``dense_points`` (K, 3)
    when given and denser than ``points`` (M, 3), with the minimum scaled by K / M so a handle is the
    same share of the cloud (3 of the model's input), else ``points`` and 3."""
    if dense_points is None or len(dense_points) <= len(points):
        return points, _MIN_HANDLE_POINTS
    dense = np.asarray(dense_points, dtype=np.float64)
    return dense, max(_MIN_HANDLE_POINTS, round(_MIN_HANDLE_POINTS * len(dense) / len(points)))


class PerceptionSource(Protocol):
    """Anything that estimates the target joint. ``needs_points``: whether it reads the cloud."""

    needs_points: bool

    def estimate(self, points: np.ndarray | None, info: dict[str, Any],
                 dense_points: np.ndarray | None = None) -> JointAxisEstimate:
        """Estimate from object points (M, 3) world frame metres (or None) and the env's info.
        ``dense_points`` (K, 3), K >= M: all isolated object points before downsampling, for
        geometry that needs more than the model's input (a source may ignore them)."""
        ...


# a hinge within 60 degrees of vertical (a door's, a washing machine's) counts as vertical
_VERTICAL_HINGE_MIN_Z = 0.5


def faces_along(plane: PartPlane | None, direction: np.ndarray, max_angle: float = 0.6) -> bool:
    """Whether ``plane``'s normal is within ``max_angle`` rad of the line of ``direction`` (3,): a
    drawer's front faces along its slide. False for no plane."""
    if plane is None:
        return False
    return abs(float(plane.outward @ unit(direction))) >= float(np.cos(max_angle))


def _target(info: dict[str, Any]) -> int:
    return int(np.asarray(info["target_joint"]).reshape(-1)[0])


def ground_truth_estimate(info: dict[str, Any]) -> JointAxisEstimate:
    """The target joint's ground truth from a capt_env info dict (world frame), pivot made canonical."""
    k = _target(info)
    axis = unit(np.asarray(info["joint_axis"], dtype=np.float64)[k])
    grasp = np.asarray(info["grasp_point"], dtype=np.float64).reshape(3)
    pivot = canonical_pivot(axis, np.asarray(info["joint_pivot"], dtype=np.float64)[k], grasp)
    return JointAxisEstimate(
        joint_type=JOINT_TYPES[int(np.asarray(info["joint_type"])[k])], direction=axis, pivot=pivot,
        state=float(np.asarray(info["joint_state"])[k]), grasp_point=grasp, confidence=1.0,
    )


class OracleSource:
    """Ground truth from ``info`` (the simulator's joints and grasp point)."""

    needs_points = False

    def estimate(self, points: np.ndarray | None, info: dict[str, Any],
                 dense_points: np.ndarray | None = None) -> JointAxisEstimate:
        return ground_truth_estimate(info)


def _perpendicular(u: np.ndarray, r: np.ndarray) -> np.ndarray:
    """The unit component of ``r`` (3,) perpendicular to the unit ``u`` (3,)."""
    return unit(r - (r @ u) * u)


def tilt(direction: np.ndarray, angle: float, rng: np.random.Generator) -> np.ndarray:
    """``direction`` (3,) rotated by ``angle`` radians about a uniformly random perpendicular axis."""
    u = unit(direction)
    perp = _perpendicular(u, rng.normal(size=3))
    return np.cos(angle) * u + np.sin(angle) * perp


class NoisyOracleSource:
    """Ground truth plus noise of the magnitudes in :class:`NoiseConfig`, seeded (see its models).

    ``gaussian``: the direction is tilted by ``|N(0, direction_rad)|`` radians, the pivot, state and
    grasp point get Gaussian offsets, all redrawn at every estimate. ``fixed_offset``: errors of
    exactly the configured sizes, their directions and signs drawn at the first estimate after
    :meth:`reset` and held until the next. In both, the grasp point moves ``grasp_outward_m`` along
    :func:`~capt_env.wrappers.estimate.away_from_joint`, and the noisy pivot is then made canonical
    again (closest to the noisy grasp point), so only the off-axis part of the pivot noise remains.
    """

    needs_points = False

    def __init__(self, noise: NoiseConfig, seed: int = 0) -> None:
        self.noise = noise
        self.rng = np.random.default_rng(seed)
        self._held: dict[str, Any] | None = None  # fixed_offset: this episode's random directions

    def reset(self) -> None:
        """A new episode: ``fixed_offset`` draws new error directions at the next estimate."""
        self._held = None

    def estimate(self, points: np.ndarray | None, info: dict[str, Any],
                 dense_points: np.ndarray | None = None) -> JointAxisEstimate:
        gt = ground_truth_estimate(info)
        n, rng = self.noise, self.rng
        outward = n.grasp_outward_m * away_from_joint(gt)
        if n.model == "fixed_offset":
            if self._held is None:
                self._held = {"tilt": rng.normal(size=3), "pivot": rng.normal(size=3),
                              "grasp": unit(rng.normal(size=3)), "sign": float(rng.choice([-1.0, 1.0]))}
            h, u = self._held, unit(gt.direction)
            direction = np.cos(n.direction_rad) * u + np.sin(n.direction_rad) * _perpendicular(u, h["tilt"])
            grasp = gt.grasp_point + outward + n.grasp_m * h["grasp"]
            shifted = gt.pivot + n.pivot_m * _perpendicular(u, h["pivot"])
            state = gt.state + h["sign"] * n.state
        else:
            direction = tilt(gt.direction, abs(float(rng.normal(0.0, n.direction_rad))), rng)
            grasp = gt.grasp_point + outward + rng.normal(0.0, n.grasp_m, size=3)
            shifted = gt.pivot + rng.normal(0.0, n.pivot_m, size=3)
            state = gt.state + float(rng.normal(0.0, n.state))
        pivot = canonical_pivot(direction, shifted, grasp)
        return JointAxisEstimate(gt.joint_type, direction, pivot, state, grasp, confidence=1.0)


class CaptSource:
    """CAPT (``perception.inference.ArticulationEstimator``) on the isolated object points.

    The checkpoint is loaded on the first call. The target joint's channel is the env's target joint
    index; the grasp point is the handle standing off the plane of the points CAPT labels as that
    joint's moving part (``handle_point``), else the far edge of those points (all points if it
    labels none). With ``order_stacked_parts`` and a model of several prismatic joints (a drawer
    stack, numbered from the bottom), the grasp point is instead the target-index-th handle from
    the bottom on the stack's front when that many are in view (``stacked_parts``).
    The axis sign is set so that opening moves the part away from its body
    (``opening_direction``): CAPT often gets a hinge's sign wrong while the line is right.
    With ``dense_geometry`` handles are looked for among all isolated points (``dense_points``), not
    only the model's downsampled input, where a handle is a handful of points that one draw keeps
    and the next loses (the grasp point then falls back to the part's far edge); the minimum
    handle size scales with the density, so it is the same share of the cloud.
    With ``slide_along_front`` a prismatic part slides along the outward normal of its flat front
    (the stack's front for stacked drawers) when that front faces along CAPT's direction: a plane
    fitted to hundreds of points is steadier than the per-point votes, a few degrees of which
    make a pulled drawer bind or slip out of the fingers.
    Successive estimates within an episode are fused (see ``estimate_fusion``);
    :meth:`reset` starts a new episode.
    """

    needs_points = True

    def __init__(self, checkpoint: str, seed: int = 0, hinge_on_part_edge: bool = False,
                 order_stacked_parts: bool = False, dense_geometry: bool = False,
                 slide_along_front: bool = False, panel_max_state: float = 0.0) -> None:
        self.checkpoint = checkpoint
        self.seed = seed
        self.hinge_on_part_edge = hinge_on_part_edge
        self.order_stacked_parts = order_stacked_parts
        self.dense_geometry = dense_geometry
        self.slide_along_front = slide_along_front
        self.panel_max_state = panel_max_state
        self._estimator: Any = None
        self._fusion = EstimateFusion()

    def reset(self) -> None:
        """Forget the previous episode's estimates."""
        self._fusion.reset()

    @property
    def estimator(self) -> Any:
        """The :class:`perception.inference.ArticulationEstimator` of ``checkpoint`` (loaded on first
        use)."""
        return self._load()

    def _load(self) -> Any:
        if self._estimator is None:
            from perception.inference import ArticulationEstimator  # lazy: only the capt source

            self._estimator = ArticulationEstimator.from_checkpoint(self.checkpoint, seed=self.seed)
        return self._estimator

    @staticmethod
    def _stacked_handle(points: np.ndarray, geometry: np.ndarray, min_points: int, result: Any,
                        model: Any, k: int,
                        direction: np.ndarray) -> tuple[PartPlane | None, np.ndarray | None]:
        """(front plane, k-th handle from the bottom among ``geometry`` points) of a stack of
        prismatic parts, or (None, None) when the model has fewer than two prismatic joints, neither
        the stacked parts together nor the target alone are flat and face along the slide
        ``direction``, or fewer than k + 1 handles are in view."""
        stacked = [int(c) for c, t in zip(model.joint_child_parts, model.joint_types, strict=False)
                   if t == "prismatic"]
        if len(stacked) < 2:
            return None, None
        labels = np.asarray(result.part_labels)
        front = points[np.isin(labels, stacked)]
        plane = part_plane(points, front)
        if not faces_along(plane, direction):
            # the union is not flat when CAPT gave a drawer some of the carcass's top or side (drawer
            # seed 108, three drawers): the target's own front is the stack's front plane too
            front = points[labels == int(model.joint_child_parts[k])]
            plane = part_plane(points, front)
            if not faces_along(plane, direction):
                return None, None
        # counting from the bottom, a missed handle names the next one up: a low or partly hidden bar
        # can show far fewer points than a lone handle must (drawer seed 30: 26 where 48 are asked),
        # so a quarter of that counts here (150 unseen resets: grasp point over 10 cm off 12 -> 7)
        fewest = max(_MIN_HANDLE_POINTS, min_points // 4)
        handle = kth_handle_from_bottom(geometry, front, k, plane=plane, min_points=fewest)
        return (plane, handle) if handle is not None else (None, None)

    def estimate(self, points: np.ndarray | None, info: dict[str, Any],
                 dense_points: np.ndarray | None = None) -> JointAxisEstimate:
        if points is None:
            raise ValueError("the capt source needs the object's points")
        geometry, min_points = handle_search_points(points, dense_points if self.dense_geometry else None)
        est = self._load()
        result = est.predict(np.asarray(points, dtype=np.float64))
        k = min(_target(info), len(result.joints) - 1)
        joint = result.joints[k]
        child_parts = getattr(est.config.model, "joint_child_parts", None)
        moving = points
        if child_parts is not None and k < len(child_parts):
            mask = np.asarray(result.part_labels) == int(child_parts[k])
            if mask.sum() >= 3:
                moving = points[mask]
        direction = unit(joint.direction)
        plane, grasp = None, None
        if self.order_stacked_parts and joint.type == "prismatic" and child_parts is not None:
            plane, grasp = self._stacked_handle(points, geometry, min_points, result, est.config.model,
                                                k, direction)
        if grasp is None:
            plane = part_plane(points, moving)
            if joint.type == "prismatic" and not faces_along(plane, direction):
                plane = None  # an open drawer's largest plane is its bottom or a side, not its front
        panel = moving  # the flat panel the moving part lies on (a closed door's whole front)
        if plane is not None and self.hinge_on_part_edge and joint.type == "revolute":
            if abs(float(joint.state)) < self.panel_max_state:
                panel = coplanar_panel(points, moving, plane)
            # the part's own points, not the panel: rectangles fitted to the panel turned the line
            # 5-11 deg off during pulls (CAPT's state lags, so the panel was grown on a door already
            # 0.4-0.6 rad open): cabinet door seeds 153, 178 and 181 failed with it, opened without
            direction = edge_aligned_direction(direction, plane, moving)
        if grasp is None and plane is not None:
            # a bar is centred across its thickness too (the cameras see one side of it, where the
            # points' centroid sits), except on a part swinging about a horizontal hinge (an oven
            # door, a lid): measured, that moved an oven's grasp point off its bar
            across = joint.type == "prismatic" or abs(float(direction[2])) >= _VERTICAL_HINGE_MIN_Z
            grasp = handle_point(geometry, panel, plane=plane, min_points=min_points,
                                 centre_across=across)
        from_handle = grasp is not None
        if plane is not None and joint.type == "prismatic":
            # before the grasp point: the front-most points along a wrongly signed slide are the back
            # (a prismatic opening direction does not depend on the pivot or grasp point)
            if self.slide_along_front:
                direction = unit(plane.outward)
            else:
                pivot_in = np.asarray(joint.pivot, dtype=np.float64)
                direction = opening_direction(joint.type, direction, pivot_in, pivot_in, plane.outward)
        if grasp is None:
            grasp = grasp_point_of_part(moving, joint.type, direction, np.asarray(joint.pivot))
        pivot = canonical_pivot(direction, np.asarray(joint.pivot, dtype=np.float64), grasp)
        if plane is not None and self.hinge_on_part_edge and joint.type == "revolute":
            direction, pivot = hinge_on_edge(direction, grasp, plane, moving, pivot=pivot,
                                             panel_points=panel)
        if plane is not None and joint.type == "revolute":
            direction = opening_direction(joint.type, direction, pivot, grasp, plane.outward)
        return self._fusion.update(JointAxisEstimate(joint.type, direction, pivot, float(joint.state),
                                                     grasp, float(joint.confidence)), from_handle)


def make_source(source: str, noise: NoiseConfig, checkpoint: str | None, seed: int,
                hinge_on_part_edge: bool = False, order_stacked_parts: bool = False,
                dense_geometry: bool = False, slide_along_front: bool = False,
                panel_max_state: float = 0.0) -> PerceptionSource:
    """The source named ``source`` ("oracle", "noisy_oracle", "capt")."""
    if source == "oracle":
        return OracleSource()
    if source == "noisy_oracle":
        return NoisyOracleSource(noise, seed)
    if source == "capt":
        if checkpoint is None:
            raise ValueError("source 'capt' needs a checkpoint path")
        return CaptSource(checkpoint, seed, hinge_on_part_edge, order_stacked_parts, dense_geometry,
                          slide_along_front, panel_max_state)
    raise ValueError(f"unknown perception source {source!r}")
