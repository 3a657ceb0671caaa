#!/usr/bin/env bash
# Regenerates the confusion table of docs/stroke-acceptance.md: labelled person-like paths on 500 random
# characters of the whole hanzi-writer-data package (fetched with npm), matched by the stroke matcher.
# Usage: scripts/update-acceptance-table.sh [BUILD_DIR] [SEED]   (defaults: build, 1)
set -euo pipefail
cd "$(dirname "$0")/.."
build=${1:-build}
seed=${2:-1}
data=$(bash scripts/fetch-hanzi-writer-data.sh)
"$build/bin/calligraphy" bench acceptance --data "$data" --characters 500 --seed "$seed" \
  --markdown docs/stroke-acceptance.md
