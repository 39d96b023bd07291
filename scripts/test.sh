#!/usr/bin/env bash
# Set up everything from nothing (see setup.sh), then lint and run the test suite (slow/GPU tests skipped).
set -euo pipefail
cd "$(dirname "$0")/.."
bash scripts/setup.sh --test
.venv/bin/ruff check .
.venv/bin/python -m pytest -q "$@"
