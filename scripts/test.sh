#!/usr/bin/env bash
# Set up everything from nothing (see setup.sh), then lint and run the test suite (slow/GPU tests skipped).
set -euo pipefail
cd "$(dirname "$0")/.."
bash scripts/setup.sh --test
# The real-file corpus (Meta-World 3.1.1's object files, ~37 MB, cached in data/); its tests skip
# with a message when the package registry cannot be reached.
.venv/bin/python scripts/real_objects.py data/real_objects || echo "[test] real-file corpus unavailable"
.venv/bin/ruff check .
.venv/bin/python -m pytest -q "$@"
