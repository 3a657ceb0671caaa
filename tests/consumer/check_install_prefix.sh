#!/usr/bin/env bash
# Fails when `cmake --install BUILD_DIR --prefix PREFIX` wrote anything outside PREFIX: every path in the
# install manifest must lie under it, and the site-packages of the `python3` first on PATH (pyenv, a venv)
# must have gained no calligraphy.pth (a staging install must not change the user's interpreter).
# Usage: check_install_prefix.sh BUILD_DIR PREFIX MARKER
#   MARKER  a file touched just before the install: a calligraphy.pth newer than it was written by it.
set -euo pipefail
build_dir=$1
prefix=$(realpath "$2")
marker=$3
manifest="$build_dir/install_manifest.txt"
if [[ ! -s $manifest ]]; then
  echo "no install manifest at $manifest" >&2
  exit 1
fi
outside=$(grep -v -- "^$prefix/" "$manifest" || true)
if [[ -n $outside ]]; then
  echo "cmake --install --prefix $prefix wrote outside its prefix:" >&2
  echo "$outside" >&2
  exit 1
fi
echo "install: $(wc -l <"$manifest") files, all under $prefix"
if command -v python3 >/dev/null 2>&1; then
  site=$(python3 -c 'import sysconfig; print(sysconfig.get_path("purelib"))' 2>/dev/null || true)
  if [[ -n $site && -e $site/calligraphy.pth && $site/calligraphy.pth -nt $marker ]]; then
    echo "cmake --install --prefix $prefix wrote $site/calligraphy.pth (python3 on PATH: $(command -v python3))" >&2
    exit 1
  fi
fi
