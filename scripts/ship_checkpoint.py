"""Copy a trained CAPT checkpoint into perception/checkpoints/ and write its model card from the
recorded benchmark JSON (generation, training, evaluation), so the card only states measured numbers.

    .venv/bin/python scripts/ship_checkpoint.py CATEGORY
"""

from __future__ import annotations

import json
import shutil
import sys
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]


def main(category: str) -> None:
    bench = ROOT / "benchmarks"
    gen = json.loads((bench / f"generate_{category}.json").read_text())
    train = json.loads((bench / f"train_{category}_capt.json").read_text())
    perf = json.loads((bench / f"perception_{category}.json").read_text())
    table = (bench / f"perception_{category}.md").read_text()
    src = ROOT / train["best_path"]
    dst = ROOT / "perception" / "checkpoints" / f"{category}.pt"
    shutil.copyfile(src, dst)
    machine = perf["machine"]
    card = f"""# CAPT default checkpoint: {category}

- File: `perception/checkpoints/{category}.pt` ({dst.stat().st_size / 1e6:.1f} MB), loaded by
  `perception.inference.ArticulationEstimator.from_checkpoint` (weights only, no code execution).
- Trained with this project's own commands on this project's own procedural data:

```bash
{gen['command']}
{train['command']}
{perf['command']}
```

  (`bash scripts/train_default_checkpoint.sh {category} {train['epochs']}` runs the same.)
- Data: {gen['counts']} single-view clouds (train/val/test split by instance, so test shapes are
  unseen), config in `configs/generate/{category}.yaml`, seed {gen.get('seed', 0)}; generated at
  {gen['samples_per_second']:.1f} samples/s with {gen['workers']} workers.
- Training: {train['epochs_run']} epochs, best validation loss {train['best_val_loss']:.4f}, double-voting
  window (w0, w1) = {tuple(train['voting_window'])} chosen on the validation split.
- Measured on {machine['cpu_count']} CPU cores ({machine['processor']}), torch {machine['torch']}.

## Test split (unseen instances)

{table}
"""
    (dst.with_suffix(".md")).write_text(card)
    print(f"shipped {dst} and {dst.with_suffix('.md')}")


if __name__ == "__main__":
    main(sys.argv[1])
