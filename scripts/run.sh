#!/usr/bin/env bash
# The main job: set up, then render and evaluate the default scenario into runs/busy_open_sea.
set -euo pipefail
cd "$(dirname "$0")/.."
bash scripts/setup.sh
exec .venv/bin/raysim run scenarios/busy_open_sea.yaml -o runs/busy_open_sea "$@"
