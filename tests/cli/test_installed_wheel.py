"""The package works installed from its wheel, outside the repository: configs and checkpoints ship."""

from __future__ import annotations

import os
import shutil
import site
import subprocess
import sys
from pathlib import Path

import pytest

REPO = Path(__file__).resolve().parents[2]


@pytest.fixture(scope="module")
def installed(tmp_path_factory: pytest.TempPathFactory) -> Path:
    """A fresh venv holding only the built wheel; the test venv's dependencies are visible to it."""
    root = tmp_path_factory.mktemp("wheel")
    source = root / "source"  # a copy, so that the build leaves nothing in the checkout
    shutil.copytree(REPO, source, symlinks=True, ignore=shutil.ignore_patterns(
        ".venv", "data", "runs", "outputs", "build", "*.egg-info", ".git", "__pycache__", ".pytest_cache"))
    subprocess.run([sys.executable, "-m", "pip", "wheel", "--no-deps", "--no-build-isolation", "-q", "-w",
                    str(root / "dist"), str(source)], check=True, timeout=600)
    (wheel,) = (root / "dist").glob("capt_env-*.whl")
    venv = root / "venv"
    subprocess.run([sys.executable, "-m", "venv", "--without-pip", str(venv)], check=True, timeout=120)
    env_site = next((venv / "lib").glob("python*/site-packages"))
    # the dependencies, without the editable capt_env (its finder is not loaded through a .pth path)
    (env_site / "deps.pth").write_text("\n".join(site.getsitepackages()) + "\n")
    subprocess.run([sys.executable, "-m", "pip", "install", "--no-deps", "-q", "--target", str(env_site),
                    str(wheel)], check=True, timeout=600)
    return venv


def _run(venv: Path, *args: str, cwd: Path) -> subprocess.CompletedProcess:
    env = {k: v for k, v in os.environ.items() if k != "PYTHONPATH"}
    env["OMP_NUM_THREADS"] = "1"
    code = "import sys; from capt_env.cli import main; sys.exit(main(sys.argv[1:]))"
    return subprocess.run([str(venv / "bin" / "python"), "-c", code, *args], cwd=cwd, env=env,
                          capture_output=True, text=True, timeout=600)


def test_the_wheel_runs_outside_the_repository(installed: Path, tmp_path: Path) -> None:
    where = _run(installed, "doctor", cwd=tmp_path)
    code = "import capt_common.typed_yaml, capt_env; print(capt_env.__file__); print(capt_common.__file__)"
    probe = subprocess.run([str(installed / "bin" / "python"), "-c", code], cwd=tmp_path, capture_output=True,
                           text=True, timeout=60)
    paths = probe.stdout.split()
    assert len(paths) == 2, probe.stderr[-2000:]
    assert all(p.startswith(str(installed)) for p in paths), paths  # the installed copies, not the checkout
    assert where.returncode == 0, where.stderr[-2000:]
    train_help = _run(installed, "train", "--help", cwd=tmp_path)
    assert train_help.returncode == 0 and "(default: capt)" in " ".join(train_help.stdout.split())
    demo = _run(installed, "demo", "--no-policy", "--categories", "laptop", "--task", "two_cameras",
                "--out", str(tmp_path / "demo"), cwd=tmp_path)
    assert demo.returncode == 0, demo.stderr[-2000:]
    assert "laptop_episode0" in demo.stdout and list((tmp_path / "demo").glob("*.png"))
