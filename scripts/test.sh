#!/usr/bin/env bash
# Set up with the test extras and run the test suite (heavy checks live behind -m bench).
set -euo pipefail
cd "$(dirname "$0")/.."
bash scripts/setup.sh test
exec .venv/bin/python -m pytest -p no:cacheprovider "$@"
