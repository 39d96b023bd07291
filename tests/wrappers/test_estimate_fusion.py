"""Fusing successive estimates of a static joint axis."""

from __future__ import annotations

import numpy as np
import pytest

from capt_env.wrappers.estimate import JointAxisEstimate
from capt_env.wrappers.estimate_fusion import EstimateFusion


def est(direction, pivot, state=0.0, grasp=(0.3, 0.0, 0.2), confidence=1.0) -> JointAxisEstimate:
    return JointAxisEstimate("revolute", np.asarray(direction, float), np.asarray(pivot, float), state,
                             np.asarray(grasp, float), confidence)


def test_flipped_and_noisy_directions_average_to_the_axis() -> None:
    fusion = EstimateFusion()
    fusion.update(est([0.0, 0.1, 1.0], [0.0, 0.0, 0.2]))
    fused = fusion.update(est([0.0, 0.1, -1.0], [0.0, 0.0, 0.2]))  # sign flip, tilted the other way
    np.testing.assert_allclose(fused.direction, [0.0, 0.0, 1.0], atol=1e-9)


def test_pivot_and_grasp_are_weighted_means_until_the_part_moves() -> None:
    fusion = EstimateFusion(state_tolerance=0.05)
    fusion.update(est([0, 0, 1], [0.0, 0.0, 0.0], grasp=(0.3, 0.0, 0.2), confidence=1.0))
    fused = fusion.update(est([0, 0, 1], [0.0, 0.09, 0.0], grasp=(0.3, 0.06, 0.2), confidence=2.0))
    np.testing.assert_allclose(fused.grasp_point, [0.3, 0.04, 0.2], atol=1e-9)
    np.testing.assert_allclose(fused.pivot[:2], [0.0, 0.06], atol=1e-9)  # weighted mean line
    moved = fusion.update(est([0, 0, 1], [0.0, 0.06, 0.0], state=0.4, grasp=(0.2, 0.2, 0.2)))
    np.testing.assert_allclose(moved.grasp_point, [0.2, 0.2, 0.2])  # the part moved: latest grasp
    assert moved.state == 0.4


def drawer(state: float, grasp) -> JointAxisEstimate:
    return JointAxisEstimate("prismatic", np.array([-1.0, 0.0, 0.0]), np.array([0.1, -0.05, 0.09]),
                             state, np.asarray(grasp, float), 1.0)


def test_a_handle_left_behind_by_the_moving_part_is_not_trusted() -> None:
    """Drawer seed 143: as the drawer slid 0.2 m open, the handle search stayed on the cabinet's
    front where the drawer had been (x = 0.11); the handle is where the slide carried it."""
    fusion = EstimateFusion()
    for _ in range(3):
        fusion.update(drawer(0.0, (0.10, -0.05, 0.09)), from_handle=True)
    stuck = fusion.update(drawer(0.2, (0.11, -0.05, 0.07)), from_handle=True)
    np.testing.assert_allclose(stuck.grasp_point, [-0.10, -0.05, 0.09], atol=1e-9)
    # a look where the handle went is trusted again, and later looks are checked against it
    found = fusion.update(drawer(0.21, (-0.12, -0.05, 0.09)), from_handle=True)
    np.testing.assert_allclose(found.grasp_point, [-0.12, -0.05, 0.09])
    again = fusion.update(drawer(0.22, (0.11, -0.05, 0.07)), from_handle=True)
    np.testing.assert_allclose(again.grasp_point, [-0.13, -0.05, 0.09], atol=1e-9)


def test_the_handle_check_scales_with_the_part_travel() -> None:
    """A look 6 cm off where the handle should be, after a 0.3 m slide (the estimated state is a few
    centimetres noisy), is still the handle; right after a 6 cm slide it is not."""
    fusion = EstimateFusion()
    fusion.update(drawer(0.0, (0.10, -0.05, 0.09)))
    far = fusion.update(drawer(0.3, (-0.14, -0.05, 0.09)))
    np.testing.assert_allclose(far.grasp_point, [-0.14, -0.05, 0.09])
    fusion.reset()
    fusion.update(drawer(0.0, (0.10, -0.05, 0.09)))
    near = fusion.update(drawer(0.06, (0.10, -0.05, 0.09)))
    np.testing.assert_allclose(near.grasp_point, [0.04, -0.05, 0.09], atol=1e-9)


def test_bad_fusion_settings_are_refused() -> None:
    with pytest.raises(ValueError, match="handle_jump_m"):
        EstimateFusion(handle_jump_m=0.0)


def test_reset_forgets() -> None:
    fusion = EstimateFusion()
    fusion.update(est([0, 0, 1], [1.0, 0.0, 0.0]))
    fusion.reset()
    fused = fusion.update(est([0, 0, -1], [0.0, 0.0, 0.0]))
    np.testing.assert_allclose(fused.direction, [0, 0, -1])


def test_a_bad_first_look_is_outvoted() -> None:
    """First estimate: the wrong sign, a pivot on the wrong edge and a grasp point on another part;
    the next three agree with each other."""
    fusion = EstimateFusion()
    fusion.update(est([0, 0, -1], [0.2, 0.25, 0.0], grasp=(0.15, 0.16, 0.25)))
    for y in (0.01, 0.0, -0.01):
        fused = fusion.update(est([0, 0.02, 1], [0.15, -0.2 + y, 0.0], grasp=(0.04, -0.05 + y, 0.19)))
    assert fused.direction[2] > 0.99  # three votes to one
    np.testing.assert_allclose(fused.grasp_point, [0.04, -0.05, 0.19], atol=0.011)
    np.testing.assert_allclose(fused.pivot[:2], [0.15, -0.2], atol=0.011)


def test_estimates_found_on_the_handle_outvote_far_edge_fallbacks() -> None:
    """A door's handle is hidden in two looks of three (the grasp point fell back to the hinge side and
    the hinge line went to the handle side): the one look that found the handle decides."""
    fusion = EstimateFusion()
    handle, hinge = (0.05, 0.11, 0.27), (0.19, -0.27, 0.27)
    fusion.update(est([0, 0, 1], [0.19, 0.13, 0.0], grasp=(0.06, -0.25, 0.27)), from_handle=False)
    fusion.update(est([0, 0, 1], hinge, grasp=handle), from_handle=True)
    fused = fusion.update(est([0, 0, 1], [0.19, 0.13, 0.0], grasp=(0.06, -0.25, 0.27)), from_handle=False)
    np.testing.assert_allclose(fused.grasp_point, handle)
    np.testing.assert_allclose(fused.pivot[:2], hinge[:2])
    # the door turned 0.5 rad and the hand hides the handle: the handle point found before turns with
    # the door about the fused hinge (z through (0.19, -0.27))
    moved = fusion.update(est([0, 0, 1], [0.19, 0.13, 0.0], state=0.5, grasp=(0.3, -0.3, 0.27)),
                          from_handle=False)
    c, s = np.cos(0.5), np.sin(0.5)
    rel = np.array([0.05 - 0.19, 0.11 + 0.27])
    turned = [0.19 + c * rel[0] - s * rel[1], -0.27 + s * rel[0] + c * rel[1], 0.27]
    np.testing.assert_allclose(moved.grasp_point, turned, atol=1e-9)
    assert moved.grasp_point[0] < handle[0]  # towards the robot (-x): the door opened
    # with no handle ever found (a lid), every estimate counts as before
    lid = EstimateFusion()
    lid.update(est([0, 0, 1], [0.0, 0.0, 0.0], grasp=(0.3, 0.0, 0.2)), from_handle=False)
    fused = lid.update(est([0, 0, 1], [0.0, 0.1, 0.0], grasp=(0.3, 0.1, 0.2)), from_handle=False)
    np.testing.assert_allclose(fused.grasp_point, [0.3, 0.05, 0.2], atol=1e-9)



def test_moved_with_part_turns_and_slides() -> None:
    from capt_env.wrappers.estimate_fusion import moved_with_part

    p = np.array([1.0, 0.0, 0.5])
    turned = moved_with_part(p, "revolute", np.array([0.0, 0.0, 1.0]), np.zeros(3), np.pi / 2)
    np.testing.assert_allclose(turned, [0.0, 1.0, 0.5], atol=1e-12)  # right-handed about +z
    slid = moved_with_part(p, "prismatic", np.array([-1.0, 0.0, 0.0]), np.zeros(3), 0.2)
    np.testing.assert_allclose(slid, [0.8, 0.0, 0.5])
