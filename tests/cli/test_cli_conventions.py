"""CLI conventions: fast top-level help, defaults in every verb's help, one-line user errors."""

from __future__ import annotations

import subprocess
import sys
import time

from capt_env.cli import main


def _capt(*args: str) -> subprocess.CompletedProcess:
    return subprocess.run([sys.executable, "-m", "capt_env.cli", *args], capture_output=True, text=True,
                          timeout=120)


def test_top_level_help_is_fast_and_imports_no_simulator() -> None:
    t0 = time.perf_counter()
    result = _capt("--help")
    elapsed = time.perf_counter() - t0
    assert result.returncode == 0 and "inspect-object" in result.stdout
    assert elapsed < 1.0, f"capt --help took {elapsed:.2f} s"
    code = "import sys, capt_env.cli; print('mani_skill' in sys.modules)"
    probe = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, timeout=60)
    assert probe.stdout.strip() == "False"


def test_verb_help_shows_defaults(capsys) -> None:
    try:
        main(["rollout", "--help"])
    except SystemExit:
        pass
    text = " ".join(capsys.readouterr().out.split())  # argparse wraps lines
    assert "source (default: 10)" in text and "(default: 200)" in text


def test_user_errors_are_one_line_with_exit_status_2() -> None:
    result = _capt("rollout", "--categories", "foo")
    assert result.returncode == 2
    assert "Traceback" not in result.stderr
    assert result.stderr.strip().splitlines() == [
        "capt rollout: error: unknown category 'foo'; known: ['laptop', 'oven', 'washing_machine', "
        "'eyeglasses', 'drawer_cabinet', 'cabinet_door', 'sliding_panel']"]
    missing = _capt("inspect-object", "/no/such/file.urdf")
    assert missing.returncode == 2 and "Traceback" not in missing.stderr
    assert "file not found" in missing.stderr
