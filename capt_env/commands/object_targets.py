"""What an evaluation command runs on: procedural categories and user object files.

Every evaluation verb (``rollout``, ``estimate-errors``, ``generate``, ``demo``) takes
``--categories`` and, beside them, user files: ``--object PATH`` (repeatable; ``--joint``,
``--front-yaw``, ``--scale`` and ``--like`` apply to each) or ``--objects FILE.yaml`` listing several
with their own options::

    objects:
      - path: metaworld/drawer.xml      # relative to the YAML file
        name: mw_drawer                 # table label (default: the file stem)
        like: drawer_cabinet            # shipped checkpoint / policy to use (default: by joint type)
        task: {closed: upper, front_yaw: "-y"}   # TaskConfig keys of the file

Tables name each object by its label.
"""

from __future__ import annotations

import argparse
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

from capt_env.tasks.config import USER_FILE_KEYS

SLIDE_ALONG_FRONT_MIN_COS = 0.7071
"""A prismatic part whose slide is within 45 degrees of its front's normal is pulled out (a drawer);
one sliding more across its front than out of it is a sliding panel (a window sash, a sliding door)."""
_ENTRY_KEYS = {"path", "name", "like", "task"}
_FILE_TASK_KEYS = set(USER_FILE_KEYS) | {"scale", "object_xy", "object_xy_noise", "yaw_noise",
                                          "target_init_fraction", "other_init_fraction",
                                          "success_fraction", "cameras"}


@dataclass(frozen=True)
class ObjectTarget:
    """One thing to evaluate: a procedural ``category``, or a user file given by ``task`` keys
    (``object`` and its options) with the shipped model ``like`` stands for."""

    label: str
    category: str | None = None
    task: dict[str, Any] = field(default_factory=dict)
    like: str | None = None

    @property
    def is_file(self) -> bool:
        return self.category is None

    def model_category(self) -> str:
        """The category whose shipped checkpoint or policy serves this target."""
        if self.category is not None:
            return self.category
        if self.like is not None:
            return self.like
        return file_model_category(self.task)


def file_model_category(task: dict[str, Any]) -> str:
    """The shipped model that serves a user file (``task``: its TaskConfig keys), by building it
    once: ``cabinet_door`` for a revolute target joint; for a prismatic one ``drawer_cabinet`` when
    it slides out of the object's front, ``sliding_panel`` when it slides across it
    (:data:`SLIDE_ALONG_FRONT_MIN_COS`)."""
    import math

    import numpy as np

    from capt_common.typed_yaml import from_dict
    from capt_env.objects.scene import create_scene
    from capt_env.tasks.config import TaskConfig
    from capt_env.tasks.object_loading import load_object

    cfg = from_dict(TaskConfig, {"category": None, **task}, where=f"object {task['object']}")
    cfg.validate()
    loaded = load_object(create_scene(render=True), cfg, np.random.RandomState(0))  # placed by its visuals
    k = loaded.target_joint
    if loaded.joint_type_ids[k] == 0:
        return "cabinet_door"
    pose = loaded.joints[k].get_global_pose().to_transformation_matrix()
    axis = np.asarray(pose.reshape(-1, 4, 4)[0, :3, 0].cpu(), dtype=np.float64)
    azimuth = math.pi - loaded.front_yaw  # the front's outward normal, object frame
    front = np.array([math.cos(azimuth), math.sin(azimuth), 0.0])
    return "drawer_cabinet" if abs(float(axis @ front)) >= SLIDE_ALONG_FRONT_MIN_COS else "sliding_panel"


def add_object_arguments(parser: argparse.ArgumentParser, categories_default: list[str] | None,
                         with_categories: bool = True) -> None:
    """``--categories`` (unless the verb has its own category flag) plus the user-file options."""
    if with_categories:
        parser.add_argument("--categories", nargs="*", default=None,
                            help=f"procedural object categories (default: {categories_default} without "
                                 "user files, none with them)")
        parser.set_defaults(categories_default=categories_default)
    parser.add_argument("--object", action="append", default=[], metavar="PATH",
                        help="a user URDF/MJCF file (repeatable); evaluated beside any categories given")
    parser.add_argument("--objects", default=None, metavar="FILE.yaml",
                        help="YAML listing user files with their options (see docs/user_objects.md)")
    parser.add_argument("--joint", default=None, help="with --object: the joint to open (default: first)")
    parser.add_argument("--front-yaw", default=None,
                        help="with --object: azimuth (rad) of the file's front normal, or +x/-x/+y/-y")
    parser.add_argument("--scale", type=float, default=None, help="with --object: uniform scale")
    parser.add_argument("--like", default=None,
                        help="with --object: the category whose shipped model to use (default: by "
                             "joint: revolute cabinet_door, prismatic drawer_cabinet when it slides out "
                             "of the front, sliding_panel when it slides across it)")


def parse_front_yaw(value: str | None) -> float | str | None:
    """A ``--front-yaw`` argument: radians as a float, or a named axis (``"-x"``) as it is."""
    if value is None:
        return None
    try:
        return float(value)
    except ValueError:
        return value


def load_objects_yaml(path: str | Path) -> list[ObjectTarget]:
    """The user files listed in an ``--objects`` YAML (paths relative to it); bad keys are errors
    naming the file, the entry and the key."""
    import yaml

    path = Path(path)
    if not path.is_file():
        raise SystemExit(f"--objects {path}: file not found")
    raw = yaml.safe_load(path.read_text()) or {}
    entries = raw.get("objects") if isinstance(raw, dict) else None
    if not isinstance(entries, list) or not entries:
        raise SystemExit(f"--objects {path}: expected a mapping with a non-empty 'objects' list")
    out = []
    for k, entry in enumerate(entries):
        where = f"--objects {path}: objects[{k}]"
        if not isinstance(entry, dict) or "path" not in entry:
            raise SystemExit(f"{where}: expected a mapping with a 'path'")
        unknown = sorted(set(entry) - _ENTRY_KEYS)
        if unknown:
            raise SystemExit(f"{where}: unknown keys {unknown}; allowed: {sorted(_ENTRY_KEYS)}")
        task = dict(entry.get("task") or {})
        bad = sorted(set(task) - _FILE_TASK_KEYS)
        if bad:
            raise SystemExit(
                f"{where}: task keys {bad} do not apply to a file; allowed: {sorted(_FILE_TASK_KEYS)}")
        file = Path(entry["path"])
        file = file if file.is_absolute() else path.parent / file
        if not file.is_file():
            raise SystemExit(f"{where}: object file not found: {file}")
        out.append(ObjectTarget(label=str(entry.get("name") or file.stem), task={"object": str(file), **task},
                                like=entry.get("like")))
    return out


def object_targets(args: argparse.Namespace) -> list[ObjectTarget]:
    """The categories and user files of a command's arguments, in that order; at least one."""
    from capt_env.objects.registry import CATEGORIES

    targets = []
    categories = args.categories
    if categories is None:  # the verb's default categories stand in only when no user file is given
        user_files = bool(args.object or args.objects)
        categories = [] if user_files else list(getattr(args, "categories_default", None) or [])
    for category in categories:
        if category not in CATEGORIES:
            raise SystemExit(f"unknown category {category!r}; known: {list(CATEGORIES)}")
        targets.append(ObjectTarget(label=category, category=category))
    per_file = {"joint": args.joint, "front_yaw": parse_front_yaw(args.front_yaw), "scale": args.scale}
    per_file = {k: v for k, v in per_file.items() if v is not None}
    if per_file and not args.object:
        raise SystemExit(f"{sorted(per_file)} apply to --object files; give --object PATH")
    for path in args.object:
        if not Path(path).is_file():
            raise SystemExit(f"--object {path}: file not found")
        targets.append(ObjectTarget(label=Path(path).stem, task={"object": str(path), **per_file},
                                    like=args.like))
    if args.objects:
        targets.extend(load_objects_yaml(args.objects))
    if not targets:
        raise SystemExit("nothing to evaluate: give --categories, --object or --objects")
    labels = [t.label for t in targets]
    if len(set(labels)) != len(labels):
        raise SystemExit(f"two objects share a label in {labels}; name them in --objects")
    return targets


def target_task(target: ObjectTarget, overrides: dict[str, Any]) -> dict[str, Any]:
    """The task keys of one target: the command's ``--task`` overrides, then the file's own keys."""
    return {**overrides, **target.task}
