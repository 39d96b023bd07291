"""``capt`` with one field of the ``capt`` source's estimate replaced by the ground truth (diagnosis).

    python benchmarks/ab_session62/swap_one_field.py FIELD rollout ...   # FIELD: state, grasp or axis

Every look's refined and fused estimate keeps the network's and refiners' values except FIELD,
which is taken from the task's ``info``: how much of a gap to ground truth that one field explains.
``grasp_near`` / ``grasp_away``: the true grasp point only while the hand (TCP) is within / more
than ``NEAR_M`` of it.
"""

import dataclasses
import sys

import numpy as np

import capt_env.wrappers.perception_wrapper as pw
from capt_env.cli import main
from capt_env.wrappers.perception_sources import ground_truth_estimate

FIELDS = {"state": ("state",), "grasp": ("grasp_point",), "axis": ("direction", "pivot"),
          "grasp_near": ("grasp_point",), "grasp_away": ("grasp_point",)}
NEAR_M = 0.06
field = sys.argv[1]
if field not in FIELDS:
    raise SystemExit(f"FIELD must be one of {sorted(FIELDS)}, got {field!r}")
perceive = pw.CaptObservationWrapper._perceive


def perceive_with_true_field(self, obs, info):  # noqa: ANN001, ANN201 - a wrapper method's signature
    latency = perceive(self, obs, info)
    if self._estimate is not None and self.config.source == "capt":
        truth = ground_truth_estimate(info)
        if field in ("grasp_near", "grasp_away"):
            tcp = np.asarray(self.env.unwrapped.agent.tcp.pose.p[0].cpu().numpy(), dtype=np.float64)
            if (float(np.linalg.norm(tcp - truth.grasp_point)) < NEAR_M) != (field == "grasp_near"):
                return latency
        self._estimate = dataclasses.replace(self._estimate,
                                             **{name: getattr(truth, name) for name in FIELDS[field]})
    return latency


pw.CaptObservationWrapper._perceive = perceive_with_true_field
sys.exit(main(sys.argv[2:]))
