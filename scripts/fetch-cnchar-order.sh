#!/usr/bin/env bash
# Fetches cnchar-order 3.2.6 (MIT, theajack/cnchar) with `npm pack`, checks its integrity against the
# SHA-512 of the tarball, and unpacks it into a cache folder. Prints the path of cnchar.order.min.js,
# whose "char":"letters" map labels every stroke of 6,939 characters; pass it to
# `calligraphy corpus validate --cnchar FILE`.
# Usage: scripts/fetch-cnchar-order.sh [CACHE_DIR]   (default: ~/.cache/calligraphy)
set -euo pipefail
version=3.2.6
expected_sha512="xeW1MnQk9GLW9rOvgTtBLl9amyJ0MBKAuXGgbiAwC/n1MRLoxW4ZnjPL+isVsi0rV3QXlbiDQQKAnL6TsJNLhA=="
cache=${1:-${XDG_CACHE_HOME:-$HOME/.cache}/calligraphy}
target="$cache/cnchar-order-$version"

if [ -f "$target/.complete" ]; then
  echo "$target/cnchar.order.min.js"
  exit 0
fi
command -v npm >/dev/null || { echo "fetch-cnchar-order: npm not found (run scripts/install-deps.sh)" >&2; exit 1; }
mkdir -p "$cache"
work=$(mktemp -d "$cache/fetch.XXXXXX")
trap 'rm -rf "$work"' EXIT
(cd "$work" && npm pack --silent "cnchar-order@$version" >/dev/null 2>&1)
tarball="$work/cnchar-order-$version.tgz"
[ -f "$tarball" ] || { echo "fetch-cnchar-order: npm pack produced no $tarball" >&2; exit 1; }
actual=$(openssl dgst -sha512 -binary "$tarball" 2>/dev/null | base64 -w0 || true)
if [ -z "$actual" ]; then actual=$(sha512sum "$tarball" | cut -d' ' -f1 | xxd -r -p | base64 -w0); fi
if [ "$actual" != "$expected_sha512" ]; then
  echo "fetch-cnchar-order: integrity check failed for $tarball (sha512-$actual)" >&2
  exit 1
fi
mkdir -p "$work/unpacked"
tar -xzf "$tarball" -C "$work/unpacked"
[ -f "$work/unpacked/package/cnchar.order.min.js" ] || { echo "fetch-cnchar-order: no cnchar.order.min.js in $tarball" >&2; exit 1; }
rm -rf "$target"
mv "$work/unpacked/package" "$target"
touch "$target/.complete"
echo "$target/cnchar.order.min.js"
