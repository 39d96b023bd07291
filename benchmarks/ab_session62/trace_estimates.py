"""``capt`` with every look of the ``capt`` source written to a JSON trace (diagnosis).

    python benchmarks/ab_session62/trace_estimates.py OUT.json rollout ...

One row per look: step, the fused estimate's grasp point and state, the ground truth's, the grasp
point's error and the hand's (TCP's) distance to the true grasp point, and the direction error.
"""

import json
import sys

import numpy as np

import capt_env.wrappers.perception_wrapper as pw
from capt_env.cli import main
from capt_env.wrappers.perception_sources import ground_truth_estimate

out = sys.argv[1]
rows: list[dict] = []
perceive = pw.CaptObservationWrapper._perceive


def perceive_and_record(self, obs, info):  # noqa: ANN001, ANN201 - a wrapper method's signature
    latency = perceive(self, obs, info)
    e = self._estimate
    if e is not None and self.config.source == "capt":
        truth = ground_truth_estimate(info)
        tcp = np.asarray(self.env.unwrapped.agent.tcp.pose.p[0].cpu().numpy(), dtype=np.float64)
        rows.append({"step": self._steps, "est": np.round(e.grasp_point, 3).tolist(),
                     "gt": np.round(truth.grasp_point, 3).tolist(),
                     "grasp_err": float(np.linalg.norm(e.grasp_point - truth.grasp_point)),
                     "tcp_to_gt": float(np.linalg.norm(tcp - truth.grasp_point)),
                     "dir_err": float(np.degrees(np.arccos(np.clip(e.direction @ truth.direction, -1, 1)))),
                     "state": float(e.state), "gt_state": float(truth.state)})
    return latency


pw.CaptObservationWrapper._perceive = perceive_and_record
try:
    code = main(sys.argv[2:])
finally:
    with open(out, "w") as fh:
        json.dump(rows, fh)
sys.exit(code)
