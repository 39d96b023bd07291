#!/usr/bin/env bash
# Set up everything from nothing (see setup.sh), then run the main job: `capt demo`.
set -euo pipefail
cd "$(dirname "$0")/.."
bash scripts/setup.sh
# two depth cameras: with one, the Panda's hand often hides the handle (benchmarks/README.md)
.venv/bin/capt demo --task configs/tasks/two_cameras.yaml "$@"
