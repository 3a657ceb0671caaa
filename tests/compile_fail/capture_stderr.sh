#!/usr/bin/env bash
# Compiler launcher for the compile-fail targets: runs the compile command given after the file name, and
# keeps the compiler's diagnostics (its standard error) in that file, whatever the build tool adds around them.
out=$1
shift
mkdir -p "$(dirname "$out")"
"$@" 2>"$out"
status=$?
cat "$out" >&2
exit $status
