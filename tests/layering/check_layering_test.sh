#!/usr/bin/env bash
# The layering check passes on the source tree and fails on a copy with one upward include added.
set -euo pipefail
source_dir=$1
python3 "$source_dir/scripts/check-layering.py" "$source_dir"
scratch=$(mktemp -d)
trap 'rm -rf "$scratch"' EXIT
mkdir -p "$scratch/src/model"
printf '#include "calligraphy/render/renderer.hpp"\n' > "$scratch/src/model/upward.cpp"
printf '#include "trial/private_helper.hpp"\n' > "$scratch/src/model/upward_private.cpp"
if output=$(python3 "$source_dir/scripts/check-layering.py" "$scratch"); then
  echo "check-layering passed a tree with upward includes" >&2
  exit 1
fi
grep -q "src/model/upward.cpp:1: module 'model' includes 'calligraphy/render/renderer.hpp'" <<<"$output"
grep -q "src/model/upward_private.cpp:1: module 'model' includes 'trial/private_helper.hpp'" <<<"$output"
echo "check-layering: refuses the upward includes, as it should"
