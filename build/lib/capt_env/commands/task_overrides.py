"""``--task PATH``: a YAML of TaskConfig overrides applied to every category of a command (cameras,
placement, ...), shared by ``capt rollout`` and ``capt demo``."""

from __future__ import annotations

import argparse


def add_task_argument(parser: argparse.ArgumentParser) -> None:
    """Add ``--task PATH`` to a command's parser."""
    parser.add_argument("--task", default=None,
                        help="TaskConfig overrides for every object (cameras, placement, ...): a shipped "
                             "name (two_cameras, val_split, ...) or a YAML path; no category/object key (use "
                             "--categories / --object)")


def task_overrides(path: str | None) -> dict:
    """TaskConfig keys from a YAML file, applied to every category (validated when the env is made)."""
    if path is None:
        return {}
    import yaml

    from capt_env.shipped_configs import resolve_config

    path = str(resolve_config("tasks", path))
    with open(path) as fh:
        raw = yaml.safe_load(fh) or {}
    if not isinstance(raw, dict):
        raise SystemExit(f"--task {path}: expected a mapping of TaskConfig keys, got {type(raw).__name__}")
    clash = sorted({"category", "object"} & set(raw))
    if clash:
        raise SystemExit(f"--task {path}: {clash} would override --categories/--object; remove them")
    return raw
