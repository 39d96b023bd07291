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
    from capt_env.shipped_configs import resolve_config
    from capt_env.tasks.config import read_task_yaml

    try:
        raw = read_task_yaml(resolve_config("tasks", path))
    except (FileNotFoundError, ValueError) as err:
        raise SystemExit(f"--task {path}: {err}") from err
    clash = sorted({"category", "object"} & set(raw))
    if clash:
        raise SystemExit(f"--task {path}: {clash} would override --categories/--object; remove them")
    return raw
