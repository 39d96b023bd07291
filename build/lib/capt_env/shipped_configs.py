"""Configs that ship inside the package: ``--config``, ``--task`` and ``--opener`` take a name or a path.

The repository's ``configs/`` folder is installed as ``capt_env/configs`` (a link in the source
tree, copied into wheels), so commands find their default configs outside the repository too.
``resolve_config("tasks", "two_cameras")`` is ``capt_env/configs/tasks/two_cameras.yaml``; a path
to an existing file is returned as it is.
"""

from __future__ import annotations

from importlib import resources
from pathlib import Path

KINDS = ("generate", "opener", "perception", "ppo", "tasks", "wrappers")


def shipped_dir(kind: str) -> Path:
    """The folder of shipped configs of one ``kind`` (see :data:`KINDS`)."""
    if kind not in KINDS:
        raise ValueError(f"unknown config kind {kind!r}; known: {list(KINDS)}")
    return Path(str(resources.files("capt_env") / "configs" / kind))


def shipped_names(kind: str) -> list[str]:
    """Names of the shipped configs of ``kind``, sorted."""
    folder = shipped_dir(kind)
    return sorted(p.stem for p in folder.glob("*.yaml")) if folder.is_dir() else []


def resolve_config(kind: str, name_or_path: str | Path) -> Path:
    """An existing YAML file: ``name_or_path`` itself, or the shipped config of that name.

    :raises FileNotFoundError: naming the argument and listing the shipped names.
    """
    path = Path(name_or_path)
    if path.is_file():
        return path
    name = path.name[:-5] if path.name.endswith(".yaml") else path.name
    if path.parent in (Path("."), Path("configs") / kind):  # a bare name, or the repo-relative path
        shipped = shipped_dir(kind) / f"{name}.yaml"
        if shipped.is_file():
            return shipped
    raise FileNotFoundError(f"{kind} config {str(name_or_path)!r} not found: give a YAML path or one of "
                            f"{shipped_names(kind)}")
