#!/usr/bin/env bash
# Fetches the whole hanzi-writer-data 2.0.1 package (9,574 characters, Arphic Public License) with
# `npm pack`, checks its integrity against the registry's published SHA-512, and unpacks it into
# a cache folder. Prints the folder of JSON files; pass it to the loader (`--data DIR`).
# Usage: scripts/fetch-hanzi-writer-data.sh [CACHE_DIR]   (default: ~/.cache/calligraphy)
set -euo pipefail
version=2.0.1
expected_sha512="nbQwM+MaryGoq7pBMIZLCd3lFq03nXuJuwku1+6UbjL58uU+9OULVcMkoNvNuJSoIV7f1bbPRfD4D/LQa5S7qg=="
cache=${1:-${XDG_CACHE_HOME:-$HOME/.cache}/calligraphy}
target="$cache/hanzi-writer-data-$version"

if [ -f "$target/.complete" ]; then
  echo "$target"
  exit 0
fi
command -v npm >/dev/null || { echo "fetch-hanzi-writer-data: npm not found (run scripts/install-deps.sh)" >&2; exit 1; }
mkdir -p "$cache"
work=$(mktemp -d "$cache/fetch.XXXXXX")
trap 'rm -rf "$work"' EXIT
(cd "$work" && npm pack --silent "hanzi-writer-data@$version" >/dev/null 2>&1)
tarball="$work/hanzi-writer-data-$version.tgz"
[ -f "$tarball" ] || { echo "fetch-hanzi-writer-data: npm pack produced no $tarball" >&2; exit 1; }
actual=$(openssl dgst -sha512 -binary "$tarball" 2>/dev/null | base64 -w0 || true)
if [ -z "$actual" ]; then actual=$(sha512sum "$tarball" | cut -d' ' -f1 | xxd -r -p | base64 -w0); fi
if [ "$actual" != "$expected_sha512" ]; then
  echo "fetch-hanzi-writer-data: integrity check failed for $tarball (sha512-$actual)" >&2
  exit 1
fi
mkdir -p "$work/unpacked"
tar -xzf "$tarball" -C "$work/unpacked"
rm -rf "$target"
mv "$work/unpacked/package" "$target"
touch "$target/.complete"
echo "$target"
