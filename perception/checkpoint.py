"""Saving and loading trained CAPT estimators (network weights + the double-voting window, Sec. III-D).

A checkpoint file is ``torch.save`` of a plain dict, read back with ``torch.load(weights_only=True)``,
so loading never unpickles code::

    {"format_version": int, "metadata": str (JSON), "state_dict": {name: Tensor}, "extra": {...}}

``metadata`` holds ``config`` (the :class:`CaptConfig` as a dict), ``voting_window`` [w0, w1],
``category`` and ``training`` (free-form JSON: epochs, losses, ...). ``extra`` may hold training
state (optimizer tensors) for resuming and is ignored by inference. Files are written atomically.
"""

from __future__ import annotations

import json
import os
import tempfile
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import torch

from capt_common.typed_yaml import ConfigError, from_dict, to_dict
from perception.config import CaptConfig

FORMAT_VERSION = 1


class CheckpointError(RuntimeError):
    """A checkpoint cannot be used: unreadable, wrong format version, or config/weights mismatch."""


@dataclass
class Checkpoint:
    """Loaded checkpoint: config, weights (CPU tensors), voting window, category, training info."""

    config: CaptConfig
    state_dict: dict[str, torch.Tensor]
    voting_window: tuple[float, float]
    category: str = ""
    training: dict[str, Any] = field(default_factory=dict)
    extra: dict[str, Any] = field(default_factory=dict)


def save_checkpoint(path: str | Path, config: CaptConfig, state_dict: dict[str, torch.Tensor],
                    voting_window: tuple[float, float] | None = None, category: str = "",
                    training: dict[str, Any] | None = None, extra: dict[str, Any] | None = None) -> Path:
    """Write a checkpoint atomically (temporary file, then rename). ``voting_window`` defaults to the
    config's (w0, w1)."""
    path = Path(path)
    path.parent.mkdir(parents=True, exist_ok=True)
    window = voting_window if voting_window is not None else (config.voting.w0, config.voting.w1)
    metadata = {"config": to_dict(config), "voting_window": [float(window[0]), float(window[1])],
                "category": category, "training": training or {}}
    payload = {
        "format_version": FORMAT_VERSION,
        "metadata": json.dumps(metadata, sort_keys=True),
        "state_dict": {k: v.detach().cpu() for k, v in state_dict.items()},
        "extra": extra or {},
    }
    fd, tmp = tempfile.mkstemp(dir=path.parent, prefix=path.name, suffix=".tmp")
    os.close(fd)
    try:
        torch.save(payload, tmp)
        os.replace(tmp, path)
    finally:
        if os.path.exists(tmp):
            os.remove(tmp)
    return path


def _config_diff(a: dict, b: dict, prefix: str = "") -> list[str]:
    diffs = []
    for key in sorted(set(a) | set(b)):
        va, vb = a.get(key, "<missing>"), b.get(key, "<missing>")
        if isinstance(va, dict) and isinstance(vb, dict):
            diffs += _config_diff(va, vb, f"{prefix}{key}.")
        elif va != vb:
            diffs.append(f"{prefix}{key}: checkpoint {va!r} != expected {vb!r}")
    return diffs


def load_checkpoint(path: str | Path, expected_model: Any = None) -> Checkpoint:
    """Read a checkpoint safely (``weights_only=True``). If ``expected_model`` (a ModelConfig) is given,
    the stored model config must equal it. Raises :class:`CheckpointError` naming the problem."""
    path = Path(path)
    if path.is_dir():
        raise CheckpointError(f"checkpoint {path} is a directory; give the .pt file in it "
                              f"(e.g. {path}/best.pt)")
    if not path.is_file():
        raise CheckpointError(f"checkpoint not found: {path}")
    try:
        payload = torch.load(path, map_location="cpu", weights_only=True)
    except (RuntimeError, EOFError, OSError) as exc:
        text = str(exc).lower()
        if "zip" in text or "central directory" in text or isinstance(exc, (EOFError, OSError)):
            first = str(exc).split(". ")[0]
            raise CheckpointError(f"checkpoint {path} is truncated or corrupt ({path.stat().st_size} bytes); "
                                  f"copy or save it again ({first})") from exc
        raise CheckpointError(f"cannot read checkpoint {path}: {exc}") from exc
    except Exception as exc:  # noqa: BLE001 - any unpickling failure means an unusable file
        raise CheckpointError(f"cannot read checkpoint {path}: {exc}") from exc
    if not isinstance(payload, dict) or "format_version" not in payload:
        raise CheckpointError(f"{path} is not a capt-env checkpoint (no format_version)")
    version = payload["format_version"]
    if version != FORMAT_VERSION:
        raise CheckpointError(f"{path}: checkpoint format_version {version} != supported {FORMAT_VERSION}")
    try:
        metadata = json.loads(payload["metadata"])
        config = from_dict(CaptConfig, metadata["config"], where="checkpoint.config")
    except (KeyError, ValueError, ConfigError) as exc:
        raise CheckpointError(f"{path}: config in checkpoint does not match this version: {exc}") from exc
    if expected_model is not None:
        diffs = _config_diff(to_dict(config.model), to_dict(expected_model))
        if diffs:
            raise CheckpointError(f"{path}: model config mismatch: " + "; ".join(diffs))
    w0, w1 = metadata.get("voting_window", [config.voting.w0, config.voting.w1])
    return Checkpoint(config=config, state_dict=payload["state_dict"], voting_window=(float(w0), float(w1)),
                      category=metadata.get("category", ""), training=metadata.get("training", {}),
                      extra=payload.get("extra", {}))


def build_model(ckpt: Checkpoint, device: str | torch.device = "cpu") -> torch.nn.Module:
    """The :class:`CaptModel` of a checkpoint with its weights loaded, in eval mode."""
    from perception.model import CaptModel

    model = CaptModel(ckpt.config.model)
    missing, unexpected = set(model.state_dict()) - set(ckpt.state_dict), set(ckpt.state_dict) - set(
        model.state_dict())
    if missing or unexpected:
        raise CheckpointError(f"weights do not match the config: missing {sorted(missing)[:5]}, "
                              f"unexpected {sorted(unexpected)[:5]}")
    try:
        model.load_state_dict(ckpt.state_dict)
    except RuntimeError as exc:
        raise CheckpointError(f"weights do not match the config: {exc}") from exc
    return model.to(device).eval()
