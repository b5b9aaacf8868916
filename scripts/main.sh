#!/usr/bin/env bash
# Set up a virtual environment and run the main job: the paper's two-link robot.
set -euo pipefail
cd "$(dirname "$0")/.."
python3 -m venv .venv
.venv/bin/python -m pip install --quiet --upgrade pip
.venv/bin/python -m pip install --quiet -e ".[verify]"
exec .venv/bin/python -m library.main_job "${1:-results}"
