#!/usr/bin/env bash
# Fetches the whole hanzi-writer-data 2.0.1 package (9,574 characters, Arphic Public License) with
# `npm pack`, checks its integrity against the registry's published SHA-512, and unpacks it into
# a cache folder. Prints the folder of JSON files; pass it to the loader (`--data DIR`).
# Usage: scripts/fetch-hanzi-writer-data.sh [CACHE_DIR]   (default: ~/.cache/calligraphy)
set -euo pipefail
# $XDG_CACHE_HOME only when it is an absolute path (the XDG base directory specification), as the program
# looks for the folder (`calligraphy corpus build` without --data).
cache_home=${XDG_CACHE_HOME:-}
[[ $cache_home == /* ]] || cache_home=$HOME/.cache
cache=${1:-$cache_home/calligraphy}
bash "$(dirname "$0")/fetch-npm-package.sh" hanzi-writer-data 2.0.1 \
  "nbQwM+MaryGoq7pBMIZLCd3lFq03nXuJuwku1+6UbjL58uU+9OULVcMkoNvNuJSoIV7f1bbPRfD4D/LQa5S7qg==" "$cache"
