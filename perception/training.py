"""Training of CAPT (paper Sec. III-C total loss, Sec. IV): seeded loop, atomic checkpoints, resume, CSV
log, and the choice of the double-voting window (w0, w1) on the validation split after training.

Outputs in ``out_dir``: ``last.pt`` (every epoch, with optimizer/scheduler/RNG state for resuming),
``best.pt`` (lowest validation loss), ``log.csv`` (one row per epoch: losses, lr, seconds). Resume
restarts after the last finished epoch and gives the same result as an uninterrupted run on the same
device: shuffling and augmentation are seeded per (seed, epoch).
"""

from __future__ import annotations

import csv
import math
import time
from collections.abc import Sequence
from dataclasses import dataclass
from pathlib import Path

import numpy as np
import torch
from torch.utils.data import DataLoader
from tqdm import tqdm

from capt_common.typed_yaml import to_dict
from perception.checkpoint import CheckpointError, load_checkpoint, save_checkpoint
from perception.config import JOINT_TYPE_CODES, TrainConfig
from perception.data import CaptShardDataset
from perception.losses import capt_losses
from perception.model import CaptModel, CaptOutput
from perception.voting import PointPredictions, choose_voting_window

LOSS_NAMES = ("total", "seg", "dir", "pdir", "dist", "state", "motion", "pivot", "slot_type")


@dataclass(frozen=True)
class TrainResult:
    """Where the checkpoints are, the best validation loss and the chosen voting window."""

    best_path: Path
    last_path: Path
    log_path: Path
    best_val_loss: float
    voting_window: tuple[float, float]
    epochs_run: int


def resolve_device(name: str) -> torch.device:
    """"auto" -> CUDA when available, else CPU."""
    if name == "auto":
        return torch.device("cuda" if torch.cuda.is_available() else "cpu")
    return torch.device(name)


def _to(batch: dict[str, torch.Tensor], device: torch.device) -> dict[str, torch.Tensor]:
    return {k: v.to(device, non_blocking=True) for k, v in batch.items()}


def _forward(model: CaptModel, points: torch.Tensor, amp: bool) -> CaptOutput:
    if amp:
        with torch.autocast(device_type="cuda", dtype=torch.bfloat16):
            out = model(points)
        return CaptOutput(**{k: (v.float() if v is not None else None) for k, v in vars(out).items()})
    return model(points)


def run_epoch(model: CaptModel, loader: DataLoader, config: TrainConfig, device: torch.device,
              optimizer: torch.optim.Optimizer | None, amp: bool, desc: str) -> dict[str, float]:
    """One pass over ``loader``; trains when ``optimizer`` is given. Returns sample-weighted mean losses."""
    train = optimizer is not None
    model.train(train)
    sums: dict[str, float] = {}
    count = 0
    bar = tqdm(loader, desc=desc, leave=False, disable=not config.progress)
    for batch in bar:
        batch = _to(batch, device)
        with torch.set_grad_enabled(train):
            losses = capt_losses(_forward(model, batch["points"], amp), batch, config.model)
        if train:
            optimizer.zero_grad(set_to_none=True)
            losses["total"].backward()
            if config.grad_clip > 0:
                torch.nn.utils.clip_grad_norm_(model.parameters(), config.grad_clip)
            optimizer.step()
        b = batch["points"].shape[0]
        count += b
        for k, v in losses.items():
            sums[k] = sums.get(k, 0.0) + float(v.detach()) * b
        bar.set_postfix(loss=f"{sums['total'] / count:.4f}")
    return {k: v / max(count, 1) for k, v in sums.items()}


@torch.no_grad()
def collect_point_predictions(model: CaptModel, dataset: CaptShardDataset, device: torch.device,
                              batch_size: int = 16
                              ) -> tuple[list[PointPredictions], list[dict[str, np.ndarray]]]:
    """Per-point predictions (normalised frame) and ground truth of every item of ``dataset``."""
    model.eval()
    preds, gts = [], []
    for batch in DataLoader(dataset, batch_size=batch_size, shuffle=False):
        out = model(batch["points"].to(device))
        if out.dir is None:
            raise ValueError("collect_point_predictions needs a per-point variant")
        seg = out.seg_logits.argmax(-1).cpu().numpy() if out.seg_logits is not None else None
        child_parts = np.asarray(model.config.joint_child_parts)
        for i in range(batch["points"].shape[0]):
            child = None if seg is None else seg[i][:, None] == child_parts[None, :]
            preds.append(PointPredictions(batch["points"][i].numpy(), out.dir[i].cpu().numpy(),
                                          out.dist[i].cpu().numpy(), out.pdir[i].cpu().numpy(),
                                          out.state[i].cpu().numpy(), child))
            gts.append({k: batch[k][i].numpy()
                        for k in ("joint_dirs", "joint_pivots", "joint_mask", "joint_types")})
    return preds, gts


def choose_window_on(model: CaptModel, dataset: CaptShardDataset, config: TrainConfig,
                     device: torch.device) -> tuple[float, float]:
    """Grid-search (w0, w1) on ``dataset`` (validation) for ``capt``; other variants keep the config's."""
    cfg = config.model
    if not cfg.double_voting or len(dataset) == 0:
        return cfg.voting.w0, cfg.voting.w1
    preds, gts = collect_point_predictions(model, dataset, device, config.batch_size)
    types = [JOINT_TYPE_CODES.get(t, -1) for t in cfg.model.joint_types]
    # an ``any`` slot votes as the type of each validation object's own joint there
    sample_types = [np.where(np.asarray(types) >= 0, types, np.maximum(g["joint_types"], 0)) for g in gts]
    w0, w1, _ = choose_voting_window(preds, [g["joint_dirs"] for g in gts], [g["joint_pivots"] for g in gts],
                                     [g["joint_mask"] for g in gts], sample_types, cfg.voting.grid_w0,
                                     cfg.voting.grid_w1, cfg.voting.min_points)
    return w0, w1


def extend_cosine_schedule(optimizer: torch.optim.Optimizer,
                           scheduler: torch.optim.lr_scheduler.CosineAnnealingLR, epochs: int) -> None:
    """Re-plan a resumed cosine schedule over ``epochs`` in all (a run given more epochs than it
    started with): the learning rate jumps to the closed-form cosine value at the epochs already done.

    Setting ``T_max`` alone is not enough: the scheduler steps its last learning rate recursively, so a
    run that reached the end of its first plan (learning rate 0) would stay at 0.
    """
    scheduler.T_max = epochs
    factor = (1 + math.cos(math.pi * scheduler.last_epoch / epochs)) / 2
    for group, base in zip(optimizer.param_groups, scheduler.base_lrs, strict=True):
        group["lr"] = scheduler.eta_min + (base - scheduler.eta_min) * factor
    scheduler._last_lr = [group["lr"] for group in optimizer.param_groups]


def train(config: TrainConfig, data_dir: str | Path | Sequence[str | Path], out_dir: str | Path,
          resume: bool = True,
          stop_after: int | None = None, init_from: str | Path | None = None) -> TrainResult:
    """Train ``config.model`` on ``data_dir`` (shard layout of :mod:`perception.data`; several
    directories train one cross-category model) into ``out_dir``.

    ``resume``: continue from ``out_dir/last.pt`` when present (its model config must match).
    ``stop_after``: run at most this many epochs in this call (time-sliced jobs); a later call resumes.
    ``init_from``: a checkpoint whose weights start a new run (fine-tuning; its model config must
    match; the optimizer and learning-rate schedule start fresh). Its validation loss is measured
    first and it is written as ``best.pt``, so the best checkpoint is never worse than the start.
    Ignored when the run resumes from ``last.pt`` (which already descends from it).
    """
    config.validate()
    out = Path(out_dir)
    out.mkdir(parents=True, exist_ok=True)
    last_path, best_path, log_path = out / "last.pt", out / "best.pt", out / "log.csv"
    device = resolve_device(config.device)
    amp = config.amp and device.type == "cuda"
    torch.manual_seed(config.seed)
    np.random.seed(config.seed)

    mcfg = config.model.model
    train_ds = CaptShardDataset(data_dir, config.train_split, mcfg, augment=config.augment, seed=config.seed,
                                rotation=config.rotation_augmentation,
                                max_samples=config.max_train_samples, sensor_noise=config.sensor_noise)
    val_ds = CaptShardDataset(data_dir, config.val_split, mcfg, augment=False, seed=config.seed + 1,
                              max_samples=config.max_val_samples, pose=config.val_pose)
    category = "+".join(dict.fromkeys(str(c) for c in train_ds.arrays["category"]))
    model = CaptModel(mcfg).to(device)
    optimizer = torch.optim.AdamW(model.parameters(), lr=config.lr, weight_decay=config.weight_decay)
    scheduler = torch.optim.lr_scheduler.CosineAnnealingLR(optimizer, T_max=config.epochs)
    start_epoch, best_val = 0, math.inf

    if resume and last_path.exists():
        ckpt = load_checkpoint(last_path, expected_model=mcfg)
        if "optimizer" not in ckpt.extra:
            raise CheckpointError(f"{last_path} has no training state to resume from")
        model.load_state_dict(ckpt.state_dict)
        optimizer.load_state_dict(ckpt.extra["optimizer"])
        scheduler.load_state_dict(ckpt.extra["scheduler"])
        if scheduler.T_max != config.epochs:
            extend_cosine_schedule(optimizer, scheduler, config.epochs)
        start_epoch = int(ckpt.extra["epoch"]) + 1
        best_val = float(ckpt.extra["best_val"])
        torch.set_rng_state(ckpt.extra["torch_rng"])
    else:
        if log_path.exists():
            log_path.unlink()
        if init_from is not None:
            model.load_state_dict(load_checkpoint(init_from, expected_model=mcfg).state_dict)
            if len(val_ds):
                val_loader = DataLoader(val_ds, batch_size=config.batch_size, shuffle=False,
                                        num_workers=config.num_workers)
                best_val = run_epoch(model, val_loader, config, device, None, amp, "val init")["total"]
                save_checkpoint(best_path, config.model, model.state_dict(), category=category,
                                training={"train_config": to_dict(config), "data_dir": str(data_dir),
                                          "init_from": str(init_from), "epoch": -1,
                                          "val_loss": best_val})

    training_info = {"train_config": to_dict(config), "data_dir": str(data_dir),
                     "init_from": None if init_from is None else str(init_from)}
    epoch_bar = tqdm(range(start_epoch, config.epochs), desc="epochs", disable=not config.progress,
                     initial=start_epoch, total=config.epochs)
    for epoch in epoch_bar:
        if stop_after is not None and epoch >= start_epoch + stop_after:
            break
        t0 = time.perf_counter()
        train_ds.set_epoch(epoch)
        gen = torch.Generator().manual_seed(config.seed * 100_003 + epoch)
        loader = DataLoader(train_ds, batch_size=config.batch_size, shuffle=True, generator=gen,
                            num_workers=config.num_workers, drop_last=len(train_ds) > config.batch_size,
                            pin_memory=device.type == "cuda")
        tr = run_epoch(model, loader, config, device, optimizer, amp, f"train {epoch}")
        val_loader = DataLoader(val_ds, batch_size=config.batch_size, shuffle=False,
                                num_workers=config.num_workers)
        va = run_epoch(model, val_loader, config, device, None, amp, f"val {epoch}") if len(val_ds) else tr
        lr = optimizer.param_groups[0]["lr"]
        scheduler.step()
        _append_log(log_path, epoch, tr, va, lr, time.perf_counter() - t0)
        info = {**training_info, "epoch": epoch, "train_loss": tr["total"], "val_loss": va["total"]}
        if va["total"] < best_val:
            best_val = va["total"]
            save_checkpoint(best_path, config.model, model.state_dict(), category=category, training=info)
        extra = {"optimizer": optimizer.state_dict(), "scheduler": scheduler.state_dict(), "epoch": epoch,
                 "best_val": best_val, "torch_rng": torch.get_rng_state()}
        save_checkpoint(last_path, config.model, model.state_dict(), category=category, training=info,
                        extra=extra)
        epoch_bar.set_postfix(train=f"{tr['total']:.4f}", val=f"{va['total']:.4f}")

    # Choose the voting window with the best weights and store it in both checkpoints.
    if not best_path.exists():
        raise RuntimeError(f"no epoch was run and no starting checkpoint was scored: {best_path} is missing")
    best = load_checkpoint(best_path, expected_model=mcfg)
    model.load_state_dict(best.state_dict)
    window = choose_window_on(model, val_ds, config, device)
    save_checkpoint(best_path, config.model, best.state_dict, window, category, best.training)
    epochs_run = 0
    if last_path.exists():  # absent only when a run from ``init_from`` stopped before its first epoch
        last = load_checkpoint(last_path, expected_model=mcfg)
        save_checkpoint(last_path, config.model, last.state_dict, window, category, last.training,
                        last.extra)
        epochs_run = int(last.extra["epoch"]) + 1
    return TrainResult(best_path, last_path, log_path, best_val, window, epochs_run)


def epoch_seconds(log_path: str | Path) -> list[float]:
    """Wall seconds of each epoch in a run's ``log.csv`` (resumed epochs included), in epoch order."""
    with open(log_path, newline="") as fh:
        return [float(row["seconds"]) for row in csv.DictReader(fh)]


def _append_log(path: Path, epoch: int, tr: dict[str, float], va: dict[str, float], lr: float,
                seconds: float) -> None:
    header = ["epoch", *(f"train_{k}" for k in LOSS_NAMES), *(f"val_{k}" for k in LOSS_NAMES), "lr",
              "seconds"]
    new = not path.exists()
    with path.open("a", newline="") as fh:
        writer = csv.writer(fh)
        if new:
            writer.writerow(header)
        writer.writerow([epoch, *(f"{tr.get(k, 0.0):.6g}" for k in LOSS_NAMES),
                         *(f"{va.get(k, 0.0):.6g}" for k in LOSS_NAMES), f"{lr:.6g}", f"{seconds:.3f}"])
