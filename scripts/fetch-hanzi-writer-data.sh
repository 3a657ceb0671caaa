#!/usr/bin/env bash
# Fetches the whole hanzi-writer-data 2.0.1 package (9,574 characters, Arphic Public License) with
# `npm pack`, checks its integrity against the registry's published SHA-512, and unpacks it into
# a cache folder. Prints the folder of JSON files; pass it to the loader (`--data DIR`).
# Usage: scripts/fetch-hanzi-writer-data.sh [CACHE_DIR]   (default: ~/.cache/calligraphy)
set -euo pipefail
cache=${1:-${XDG_CACHE_HOME:-$HOME/.cache}/calligraphy}
bash "$(dirname "$0")/fetch-npm-package.sh" hanzi-writer-data 2.0.1 \
  "nbQwM+MaryGoq7pBMIZLCd3lFq03nXuJuwku1+6UbjL58uU+9OULVcMkoNvNuJSoIV7f1bbPRfD4D/LQa5S7qg==" "$cache"
