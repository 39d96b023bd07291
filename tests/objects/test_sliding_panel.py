"""The sliding-panel category: sashes slide across the front, over the pane behind them, within the
frame; a sash that slides up is balanced."""

from __future__ import annotations

import numpy as np

from capt_env.objects.geometry import box_corners
from capt_env.objects.registry import make_object


def _extent(link) -> tuple[np.ndarray, np.ndarray]:
    pts = np.concatenate([box_corners(b) for b in link.boxes if not b.is_handle])
    return pts.min(axis=0), pts.max(axis=0)


def test_a_sash_slides_across_the_front_within_its_frame_and_only_an_upward_one_is_balanced() -> None:
    kinds = set()
    for i in range(0, 1000, 23):
        spec = make_object("sliding_panel", i)
        body, sash = spec.links
        joint = spec.joints[0]
        axis = np.asarray(joint.axis)
        kinds.add((spec.params["kind"], spec.params["slide"]))
        assert joint.type == "prismatic" and abs(axis[0]) < 1e-12  # across the front (-x faces out)
        assert sash.balanced == (axis[2] > 0.5)  # a sash window's counterweight, none sideways
        lo, hi = _extent(sash)
        body_lo, body_hi = _extent(body)
        k = int(np.argmax(np.abs(axis)))
        moved_lo, moved_hi = lo + axis * joint.limits[1], hi + axis * joint.limits[1]
        # fully open, the sash still lies within the object's outline along its slide
        assert body_lo[k] - 1e-9 <= moved_lo[k] and moved_hi[k] <= body_hi[k] + 1e-9
    assert {s for _, s in kinds} == {"up", "left", "right"} and {k for k, _ in kinds} == {"window", "cabinet"}
