#!/usr/bin/env bash
# Runs the trainer's window tests (test_trainer.py) on a virtual X server. Exits 77, which CTest counts
# as skipped, when xvfb-run or xdotool is missing or no X server can start here.
set -u
here="$(cd "$(dirname "$0")" && pwd)"
for tool in xvfb-run xdotool python3; do
  if ! command -v "$tool" >/dev/null 2>&1; then
    echo "trainer tests skipped: $tool not found (Debian: xvfb xdotool)"
    exit 77
  fi
done
exec xvfb-run -a -s "-screen 0 1400x900x24" python3 "$here/test_trainer.py" "$@"
