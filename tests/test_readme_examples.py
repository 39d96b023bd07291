"""The README's SB3 PPO example runs as printed (a smaller rollout buffer and step count)."""

from __future__ import annotations

import re
import subprocess
import sys
from pathlib import Path

ROOT = Path(__file__).resolve().parent.parent


def _python_block_after(marker: str) -> str:
    text = (ROOT / "README.md").read_text()
    start = text.index(marker)
    return re.search(r"```python\n(.*?)```", text[start:], re.S).group(1)


def test_readme_sb3_ppo_example_trains(tmp_path: Path) -> None:
    code = _python_block_after("SB3 PPO on the wrapped env")
    assert '.learn(20_000)' in code and 'PPO("MlpPolicy", venv, verbose=1)' in code
    code = code.replace(".learn(20_000)", ".learn(64)").replace(
        'PPO("MlpPolicy", venv, verbose=1)', 'PPO("MlpPolicy", venv, verbose=1, n_steps=32, batch_size=32)')
    script = tmp_path / "readme_ppo.py"
    script.write_text(code)
    done = subprocess.run([sys.executable, str(script)], cwd=tmp_path, capture_output=True, text=True,
                          timeout=300)
    assert done.returncode == 0, done.stderr[-2000:]
    assert "total_timesteps" in done.stdout
