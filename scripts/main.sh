#!/usr/bin/env bash
# Set up a virtual environment and run the main job: the paper's two-link robot.
# Usage: bash scripts/main.sh [OUTDIR]   (default: results/ in the repository)
# Everything the job writes goes into OUTDIR; the set-up is skipped when .venv already holds
# this version of the project (a stamp keyed on pyproject.toml).
set -euo pipefail
outdir="${1:-}"
if [ -n "$outdir" ]; then                 # relative to the caller's folder, not the repository
    mkdir -p "$outdir"
    outdir="$(cd "$outdir" && pwd)"
fi
cd "$(dirname "$0")/.."
stamp=".venv/.bgmodelica-main-$(python3 -c 'import hashlib,sys; print(hashlib.sha256(open("pyproject.toml","rb").read()).hexdigest()[:16])')"
if [ ! -f "$stamp" ]; then
    python3 -m venv .venv
    .venv/bin/python -m pip install --quiet --upgrade pip
    .venv/bin/python -m pip install --quiet -e ".[verify]"
    touch "$stamp"
fi
exec .venv/bin/python -m library.main_job "${outdir:-results}"
