#!/usr/bin/env bash
# Build the documentation site (mkdocs.yml, docs/) with warnings as errors.
# Usage: bash scripts/docs.sh [SITE_DIR]   (default: a temporary folder, removed afterwards)
set -euo pipefail
cd "$(dirname "$0")/.."
python3 -m venv .venv
.venv/bin/python -m pip install --quiet -e ".[docs]"
if [ $# -ge 1 ]; then
    exec .venv/bin/mkdocs build --strict --site-dir "$1"
fi
site="$(mktemp -d)"
trap 'rm -rf "$site"' EXIT
.venv/bin/mkdocs build --strict --site-dir "$site"
echo "docs: built without warnings"
