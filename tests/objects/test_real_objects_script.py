"""``scripts/real_objects.py`` on a wheel built here (no package registry): it unpacks the folder a
source names, keeping the relative layout the files' includes rely on, and lists each object with its
options and a path relative to the listing."""

from __future__ import annotations

import zipfile
from pathlib import Path

import pytest
import yaml


def _wheel(path: Path) -> Path:
    with zipfile.ZipFile(path, "w") as zf:
        zf.writestr("pkg/assets/kitchen/items/door_chain.xml", "<mujoco/>")
        zf.writestr("pkg/assets/kitchen/meshes/door.stl", "solid door")
        zf.writestr("pkg/other/ignored.txt", "not unpacked")
    return path


def test_a_source_is_unpacked_with_its_layout_and_listed_relative_to_it(tmp_path, load_script) -> None:
    script = load_script("real_objects")
    door = ("door", "kitchen/items/door_chain.xml", "cabinet_door", {"joint": "hinge"})
    source = script.WheelSource("pkg==1.0", "pkg-1.0", "pkg/assets/", "pkg_files", (door,))
    out = tmp_path / "out"
    script.unpack(source, _wheel(tmp_path / "pkg-1.0-py3-none-any.whl"), out)
    # the mesh an include reaches with ../meshes stays beside the item folder
    assert (out / "pkg_files" / "kitchen" / "meshes" / "door.stl").is_file()
    assert not (out / "pkg_files" / "other").exists() and not (out / "other").exists()
    listing = script.write_listing(out, "mine.yaml", (source,))
    objects = yaml.safe_load(listing.read_text())["objects"]
    assert objects == [{"path": "pkg_files/kitchen/items/door_chain.xml", "name": "door",
                        "like": "cabinet_door", "task": {"joint": "hinge"}}]
    assert (listing.parent / objects[0]["path"]).is_file()


def test_a_listed_file_missing_from_its_wheel_is_an_error_naming_it(tmp_path, load_script) -> None:
    script = load_script("real_objects")
    source = script.WheelSource("pkg==1.0", "pkg-1.0", "pkg/assets/", "pkg_files",
                                (("lid", "kitchen/items/lid.xml", "laptop", {}),))
    script.unpack(source, _wheel(tmp_path / "pkg-1.0-py3-none-any.whl"), tmp_path)
    with pytest.raises(SystemExit, match="lid.xml missing from pkg==1.0"):
        script.write_listing(tmp_path, "mine.yaml", (source,))


def test_the_shipped_sources_name_pinned_wheels_and_distinct_labels(load_script) -> None:
    script = load_script("real_objects")
    sources = (script.METAWORLD, *script.OTHERS)
    assert all("==" in s.spec and s.stem.endswith(s.spec.split("==")[1]) for s in sources)
    labels = [label for s in sources for label, *_ in s.objects]
    assert len(labels) == len(set(labels))
