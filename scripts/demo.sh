#!/usr/bin/env bash
# Set up everything from nothing (see setup.sh), then run the main job: `capt demo`.
set -euo pipefail
cd "$(dirname "$0")/.."
bash scripts/setup.sh
.venv/bin/capt demo "$@"
