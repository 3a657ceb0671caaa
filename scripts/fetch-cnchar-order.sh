#!/usr/bin/env bash
# Fetches cnchar-order 3.2.6 (MIT, theajack/cnchar) with `npm pack`, checks its integrity against the
# SHA-512 of the tarball, and unpacks it into a cache folder. Prints the path of cnchar.order.min.js,
# whose "char":"letters" map labels every stroke of 6,939 characters; pass it to
# `calligraphy corpus validate --cnchar FILE`.
# Usage: scripts/fetch-cnchar-order.sh [CACHE_DIR]   (default: ~/.cache/calligraphy)
set -euo pipefail
cache=${1:-${XDG_CACHE_HOME:-$HOME/.cache}/calligraphy}
folder=$(bash "$(dirname "$0")/fetch-npm-package.sh" cnchar-order 3.2.6 \
  "xeW1MnQk9GLW9rOvgTtBLl9amyJ0MBKAuXGgbiAwC/n1MRLoxW4ZnjPL+isVsi0rV3QXlbiDQQKAnL6TsJNLhA==" \
  "$cache" cnchar.order.min.js)
echo "$folder/cnchar.order.min.js"
