#!/usr/bin/env bash
# The layering check passes on the source tree and fails on a tree with upward includes, and with front-ends
# that include a module's private header.
set -euo pipefail
source_dir=$1
python3 "$source_dir/scripts/check-layering.py" "$source_dir"
scratch=$(mktemp -d)
trap 'rm -rf "$scratch"' EXIT
mkdir -p "$scratch/src/model"
printf '#include "calligraphy/render/renderer.hpp"\n' > "$scratch/src/model/upward.cpp"
printf '#include "trial/private_helper.hpp"\n' > "$scratch/src/model/upward_private.cpp"
# analysis (the matcher, the metrics, the quiz) stands on the model only: no trial, report or study.
mkdir -p "$scratch/src/analysis"
printf '#include "calligraphy/trial/result.hpp"\n#include "calligraphy/report/pen_trace_csv.hpp"\n#include "calligraphy/study/protocol.hpp"\n#include "calligraphy/model/scene.hpp"\n' \
  > "$scratch/src/analysis/quiz.cpp"
mkdir -p "$scratch/src/study" "$scratch/src/trainer" "$scratch/src/cli" "$scratch/src/eval" "$scratch/bindings/python"
printf '#include "study/trial_record.hpp"\n#include "trainer/own.hpp"\n' > "$scratch/src/trainer/window.cpp"
printf '#include "eval/job.hpp"\n#include "trainer/trainer.hpp"\n#include "study/names.hpp"\n' > "$scratch/src/cli/command.cpp"
printf '#include "calligraphy/study/protocol.hpp"\n#include "local.hpp"\n#include "eval/job.hpp"\n' \
  > "$scratch/bindings/python/module.cpp"
if output=$(python3 "$source_dir/scripts/check-layering.py" "$scratch"); then
  echo "check-layering passed a tree with upward includes" >&2
  exit 1
fi
grep -q "src/model/upward.cpp:1: module 'model' includes 'calligraphy/render/renderer.hpp'" <<<"$output"
grep -q "src/model/upward_private.cpp:1: module 'model' includes 'trial/private_helper.hpp'" <<<"$output"
grep -q "src/analysis/quiz.cpp:1: module 'analysis' includes 'calligraphy/trial/result.hpp'" <<<"$output"
grep -q "src/analysis/quiz.cpp:2: module 'analysis' includes 'calligraphy/report/pen_trace_csv.hpp'" <<<"$output"
grep -q "src/analysis/quiz.cpp:3: module 'analysis' includes 'calligraphy/study/protocol.hpp'" <<<"$output"
grep -q "src/trainer/window.cpp:1: the front-end src/trainer includes 'study/trial_record.hpp'" <<<"$output"
grep -q "src/cli/command.cpp:3: the front-end src/cli includes 'study/names.hpp'" <<<"$output"
grep -q "bindings/python/module.cpp:3: the front-end bindings/python includes 'eval/job.hpp'" <<<"$output"
# What a front-end may include is not refused: its own headers, the parts it runs, public headers.
if grep -q "analysis/quiz.cpp:4\|window.cpp:2\|command.cpp:1\|command.cpp:2\|module.cpp:1\|module.cpp:2" <<<"$output"; then
  echo "check-layering refused an include a front-end may make:" >&2
  echo "$output" >&2
  exit 1
fi
echo "check-layering: refuses the upward includes and front-ends on private headers, as it should"
