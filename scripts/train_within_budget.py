"""Train CAPT for as many epochs as a wall-clock budget allows, with the cosine schedule annealed to
its end: one epoch is run and timed, then the run is re-planned (:func:`perception.training.train`
resumes from ``last.pt`` and :func:`extend_cosine_schedule` stretches the schedule) over the epochs
that fit in what is left. Simulator-free: it imports ``perception`` only, so it runs on a machine
with PyTorch and PyYAML alone (a lent GPU).

    python scripts/train_within_budget.py --config configs/perception/capt_cross_category.yaml \
        --data runs/device_pack/* --out runs/cross/capt_cross_v3 --seconds 420 \
        --init-checkpoint runs/cross/capt_cross_v2/best.pt --device cuda --batch-size 32 --num-workers 12
"""

from __future__ import annotations

import argparse
import json
import math
import platform
import sys
import time
from dataclasses import replace
from pathlib import Path

import torch

from capt_common.typed_yaml import load_yaml
from perception.config import TrainConfig
from perception.training import epoch_seconds, train

RESERVE_S = 30.0  # the final voting-window search and checkpoint writes


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--config", type=Path, required=True, help="TrainConfig YAML")
    parser.add_argument("--data", type=Path, nargs="+", required=True, help="shard directories")
    parser.add_argument("--out", type=Path, required=True)
    parser.add_argument("--seconds", type=float, required=True, help="wall-clock budget for the whole run")
    parser.add_argument("--max-epochs", type=int, default=400)
    parser.add_argument("--init-checkpoint", type=Path, default=None)
    parser.add_argument("--device", default="auto")
    parser.add_argument("--batch-size", type=int, default=None)
    parser.add_argument("--lr", type=float, default=None)
    parser.add_argument("--num-workers", type=int, default=None)
    args = parser.parse_args()

    start = time.perf_counter()
    config = load_yaml(TrainConfig, args.config)
    overrides = {"device": args.device, "progress": False}
    for key in ("batch_size", "lr", "num_workers"):
        if getattr(args, key) is not None:
            overrides[key] = getattr(args, key)
    config = replace(config, **overrides)
    data = [str(d) for d in args.data]
    first = replace(config, epochs=args.max_epochs)
    train(first, data, args.out, resume=False, stop_after=1, init_from=args.init_checkpoint)
    per_epoch = max(epoch_seconds(args.out / "log.csv"))
    left = args.seconds - (time.perf_counter() - start) - RESERVE_S
    epochs = max(1, min(args.max_epochs, 1 + math.floor(left / per_epoch)))
    print(f"epoch 0 took {per_epoch:.1f} s; planning {epochs} epochs", flush=True)
    result = train(replace(config, epochs=epochs), data, args.out, resume=True)
    report = {
        "command": " ".join(sys.argv),
        "machine": {"platform": platform.platform(), "torch": torch.__version__,
                    "device": torch.cuda.get_device_name() if torch.cuda.is_available() else "cpu"},
        "train_config": {**overrides, "epochs": epochs},
        "epochs_run": result.epochs_run,
        "best_val_loss": result.best_val_loss,
        "voting_window": list(result.voting_window),
        "epoch_seconds": epoch_seconds(args.out / "log.csv"),
        "wall_seconds": round(time.perf_counter() - start, 1),
        "init_from": None if args.init_checkpoint is None else str(args.init_checkpoint),
        "data": data,
    }
    (args.out / "train.json").write_text(json.dumps(report, indent=2))
    print(json.dumps({k: report[k] for k in ("epochs_run", "best_val_loss", "wall_seconds")}))


if __name__ == "__main__":
    main()
