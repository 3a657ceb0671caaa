#!/usr/bin/env bash
# Benchmark: a study of SUBJECTS simulated subjects x TRIALS trials made with `calligraphy session run` (one
# run per subject, JOBS at a time), its bytes on disk, then `calligraphy report` of it (the tidy tables
# --csv and the per-trial pages --out) under /usr/bin/time -v: wall time and peak resident memory; then,
# when python3 imports the module (PYTHONPATH=build/python), the Python page (calligraphy.study_report of
# calligraphy.study.load) and every trace read through Study.iter_samples, each timed the same way.
#
#   bash bench/study_scale.sh build/bin/calligraphy /tmp/scale [SUBJECTS=100] [TRIALS=200] [JOBS=2]
#
# LONG=1 makes a study of another shape: each trial writes four characters (about four times the samples).
# A benchmark, not a test: nothing is asserted; the figures go in docs/experiments.md ("Scale").
# WORK is replaced. An existing WORK/study of the same size is kept (KEEP_STUDY=1) to time the report again.
set -euo pipefail

cli=$(realpath "${1:?usage: study_scale.sh CALLIGRAPHY WORK [SUBJECTS] [TRIALS] [JOBS]}")
work=${2:?usage: study_scale.sh CALLIGRAPHY WORK [SUBJECTS] [TRIALS] [JOBS]}
subjects=${3:-100}
trials=${4:-200}
jobs=${5:-2}

if [[ "${KEEP_STUDY:-0}" != 1 ]]; then
  rm -rf "$work"
  mkdir -p "$work"
  # Ten characters under two conditions, TRIALS / 20 repetitions each: TRIALS test trials a subject.
  repetitions=$(( trials / 20 > 0 ? trials / 20 : 1 ))
  items='"大", "山", "木", "中", "十", "人", "口", "九", "乙", "永"'
  max_duration_s=60
  if [[ "${LONG:-0}" == 1 ]]; then
    max_duration_s=240
    items='"大山木中", "十人口九", "乙永大山", "木中十人", "口九乙永", "山木中十", "人口九乙", "永大山木", "中十人口", "九乙永大"'
  fi
  cat > "$work/scale.json" <<EOF
{"format": "calligraphy-study-protocol", "version": 1, "name": "scale",
 "conditions": [{"name": "vision", "mode": "vision"}, {"name": "haptic", "mode": "haptic"}],
 "test": {"characters": [$items],
          "conditions": ["vision", "haptic"], "repetitions": $repetitions},
 "order": {"conditions": "fixed", "characters": "fixed"},
 "trial": {"max_duration_s": $max_duration_s, "rate_hz": 1000}}
EOF
  start=$(date +%s.%N)
  seq -f "S%03g" 1 "$subjects" |
    xargs -P "$jobs" -I{} "$cli" session run "$work/scale.json" --subject {} --writer simulated \
      --out "$work/study" > /dev/null
  end=$(date +%s.%N)
  printf 'made %d subjects x %d trials with session run (%d at a time): %.0f s\n' "$subjects" \
    "$(( repetitions * 20 ))" "$jobs" "$(echo "$end - $start" | bc)"
fi

files=$(find "$work/study" -type f | wc -l)
traces=$(find "$work/study" -name '*.trace.h5' -printf '%s\n' | awk '{s += $1} END {print s + 0}')
records=$(find "$work/study" -path '*/trials/*.json' -printf '%s\n' | awk '{s += $1} END {print s + 0}')
figures=$(find "$work/study" -name '*.svg' -printf '%s\n' | awk '{s += $1} END {print s + 0}')
printf 'on disk: %s bytes in blocks (du), %s bytes of files (%d files: traces %s, records %s, SVGs %s)\n' \
  "$(du -s --block-size=1 "$work/study" | cut -f1)" "$(du -s --apparent-size --block-size=1 "$work/study" | cut -f1)" \
  "$files" "$traces" "$records" "$figures"

rm -rf "$work/tables" "$work/trials.html" "$work/trials_files"
mkdir -p "$work/tables"
/usr/bin/time -v "$cli" report "$work/study" --csv "$work/tables" --out "$work/trials.html" \
  2> "$work/report.time"
grep -E 'Elapsed \(wall clock\)|Maximum resident set size|User time|System time|Percent of CPU' "$work/report.time"
printf 'pages: %s bytes\n' "$(du -s --apparent-size --block-size=1 "$work/trials_files" | cut -f1)"

python=${PYTHON:-/usr/bin/python3}
if "$python" -c "import calligraphy.study" 2> /dev/null; then
  rm -rf "$work/python-report"
  /usr/bin/time -v "$python" -c "import sys, calligraphy.study as s, calligraphy.study_report as r
r.write_report(s.load(sys.argv[1]), sys.argv[2])" "$work/study" "$work/python-report" 2> "$work/python-report.time"
  printf 'Python page (study_report.write_report of study.load):\n'
  grep -E 'Elapsed \(wall clock\)|Maximum resident set size' "$work/python-report.time"
  /usr/bin/time -v "$python" -c "import sys, time, calligraphy.study as s
study, start, samples = s.load(sys.argv[1]), time.perf_counter(), 0
for _, trace in study.iter_samples():
    samples += len(trace)
seconds = time.perf_counter() - start
print(f'Study.iter_samples: {len(study.trials)} traces, {samples} samples in {seconds:.1f} s: '
      f'{samples / seconds / 1e6:.1f} M samples/s')" "$work/study" 2> "$work/python-samples.time"
  grep -E 'Elapsed \(wall clock\)|Maximum resident set size' "$work/python-samples.time"
fi
