#!/usr/bin/env bash
# Fails when a program built against calligraphy::haptics is linked with, or needs at run time, a library a
# haptic application does not use: OpenSSL's libssl (TLS), hidapi or libusb (calligraphy::phantom_usb),
# zinnia (legibility). OpenSSL's libcrypto is allowed: a trial record names its scene and a replay's teacher
# by SHA-256 (trial/recorded_trial.hpp), and a haptic application reads and re-runs records. The link lines are read from the consumer's build.ninja
# (the linker may drop an unused library, so the programs' NEEDED entries alone would not show it).
# Usage: check_link_line.sh BUILD_DIR PROGRAM...
set -euo pipefail
build_dir=$1
shift
forbidden='ssl|hidapi|usb-1.0|libusb|zinnia'
status=0
link_lines=$(grep -a 'LINK_LIBRARIES = ' "$build_dir/build.ninja")
if [[ -z $link_lines ]]; then
  echo "no link line found in $build_dir/build.ninja" >&2
  exit 1
fi
if grep -Eq -- "$forbidden" <<<"$link_lines"; then
  echo "a link line names more than the haptics package should:" >&2
  grep -E -- "$forbidden" <<<"$link_lines" >&2
  status=1
fi
for program in "$@"; do
  needed=$(readelf -d "$program" | sed -n 's/.*(NEEDED).*\[\(.*\)\]/\1/p' | tr '\n' ' ')
  if grep -Eq -- "$forbidden" <<<"$needed"; then
    echo "$program needs more than the haptics package should: $needed" >&2
    status=1
  else
    echo "$program links $(grep -Eo -- '-l[a-z0-9_.+-]+' <<<"$link_lines" | sort -u | tr '\n' ' ')and needs: $needed"
  fi
done
exit $status
