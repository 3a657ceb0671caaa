#!/usr/bin/env bash
# Fails when a program built against calligraphy::haptics needs a library a haptic application does not use:
# OpenSSL (the research package's protocol hashes), hidapi or libusb (calligraphy::phantom_usb), zinnia.
# Usage: check_link_line.sh PROGRAM...
set -euo pipefail
status=0
for program in "$@"; do
  needed=$(readelf -d "$program" | sed -n 's/.*(NEEDED).*\[\(.*\)\]/\1/p' | tr '\n' ' ')
  if grep -Eq 'libcrypto|libssl|libhidapi|libusb|libzinnia' <<<"$needed"; then
    echo "$program needs more than the haptics package should: $needed" >&2
    status=1
  else
    echo "$program needs: $needed"
  fi
done
exit $status
