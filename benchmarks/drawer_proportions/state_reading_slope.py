"""How a model's raw state reading follows the truth on a dataset's test clouds: the line fitted to
read against true state (slope 1, intercept 0 is a perfect reading), the median error and the
target joint's direction error median (a diagnosis tool; ``capt evaluate`` gives the tables).
Prismatic states in metres, revolute ones in degrees. The model's joint slot is the cloud's target
joint's index (clouds of one-slot models: slot 0).

    python benchmarks/drawer_proportions/state_reading_slope.py DATA_DIR [CHECKPOINT]
"""

from __future__ import annotations

import sys
from pathlib import Path

import numpy as np

from perception.config import JOINT_TYPE_CODES
from perception.inference import ArticulationEstimator


def main(data: str, checkpoint: str = "perception/checkpoints/drawer_cabinet.pt") -> None:
    est = ArticulationEstimator.from_checkpoint(checkpoint)
    rows, revolute = [], False
    for shard in sorted(Path(data, "test").glob("*.npz")):
        d = np.load(shard)
        for i in range(len(d["points"])):
            t = int(d["target_joint"][i])
            joints = est.predict(d["points"][i]).joints
            joint = next((j for j in joints if j.joint_index == t), joints[0])
            cos = float(np.clip(joint.direction @ d["joint_dirs"][i, t], -1.0, 1.0))
            revolute = int(d["joint_types"][i, t]) == JOINT_TYPE_CODES["revolute"]
            unit = np.degrees if revolute else float
            rows.append((unit(float(d["joint_states"][i, t])), unit(joint.state), np.degrees(np.arccos(cos))))
    r = np.asarray(rows)
    slope, intercept = np.polyfit(r[:, 0], r[:, 1], 1)
    unit = "deg" if revolute else "m"
    print(f"{data}: {len(r)} clouds, slope {slope:.2f}, intercept {intercept:.3f} {unit}, state median error "
          f"{np.median(np.abs(r[:, 0] - r[:, 1])):.3f} {unit} (true {r[:, 0].min():.2f}-{r[:, 0].max():.2f} "
          f"{unit}), direction median {np.median(r[:, 2]):.1f} deg")


if __name__ == "__main__":
    main(*sys.argv[1:])
