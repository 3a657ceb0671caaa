#!/usr/bin/env bash
# Fetches one npm package version with `npm pack`, checks the tarball against the registry's published
# SHA-512 (its `dist.integrity`), and unpacks it into CACHE_DIR/NAME-VERSION (once; later calls reuse it).
# Prints that folder. Shared by fetch-hanzi-writer-data.sh and fetch-cnchar-order.sh.
# Usage: scripts/fetch-npm-package.sh NAME VERSION SHA512_BASE64 CACHE_DIR [FILE_THAT_MUST_EXIST]
set -euo pipefail
name=$1 version=$2 expected_sha512=$3 cache=$4 required=${5:-}
target="$cache/$name-$version"
say() { echo "fetch $name: $*" >&2; }

if [ -f "$target/.complete" ]; then
  echo "$target"
  exit 0
fi
command -v npm >/dev/null || { say "npm not found (run scripts/install-deps.sh)"; exit 1; }
mkdir -p "$cache"
work=$(mktemp -d "$cache/fetch.XXXXXX")
trap 'rm -rf "$work"' EXIT
(cd "$work" && npm pack --silent "$name@$version" >/dev/null 2>&1)
tarball="$work/$name-$version.tgz"
[ -f "$tarball" ] || { say "npm pack produced no $tarball"; exit 1; }
actual=$(openssl dgst -sha512 -binary "$tarball" 2>/dev/null | base64 -w0 || true)
if [ -z "$actual" ]; then actual=$(sha512sum "$tarball" | cut -d' ' -f1 | xxd -r -p | base64 -w0); fi
if [ "$actual" != "$expected_sha512" ]; then
  say "integrity check failed for $tarball (sha512-$actual, expected sha512-$expected_sha512)"
  exit 1
fi
mkdir -p "$work/unpacked"
tar -xzf "$tarball" -C "$work/unpacked"
if [ -n "$required" ] && [ ! -f "$work/unpacked/package/$required" ]; then
  say "no $required in $tarball"
  exit 1
fi
rm -rf "$target"
mv "$work/unpacked/package" "$target"
touch "$target/.complete"
echo "$target"
