#!/usr/bin/env bash
# Fails (exit 1, listing file:line) when a tracked file cites something a reader of the repository
# cannot follow: a notes file that is not in the repository (REFERENCE.md, seed-paper.txt, the
# shared/reference folder) or a work item of this project ("issue 5", "issues 3", "Deliver 1",
# "work item 2"). Cite the original source instead (docs/references.md lists them) and say what the
# code does and why. Also fails when the README, the docs or the examples name a public header
# (calligraphy/<module>/<name>.hpp) that does not exist.
#
# An issue of ANOTHER project may be named as "<project> issue #N" (e.g. "libnifalcon issue #27"):
# the "#" keeps it out of the patterns below. This script itself is exempt, since it has to spell
# the patterns out.
set -euo pipefail
cd "$(dirname "$0")/.."

self=scripts/check-docs.sh
# POSIX ERE; "(^|[^[:alnum:]_])" stands in for a word boundary (so "tissue 5" does not count).
pattern='REFERENCE\.md|seed-paper|shared/reference'
pattern+='|(^|[^[:alnum:]_])[Ii]ssues? [0-9]+'
pattern+='|(^|[^[:alnum:]_])Deliver(ables?)? [0-9]+'
pattern+='|(^|[^[:alnum:]_])[Ww]ork items? [0-9]+'

if git rev-parse --is-inside-work-tree >/dev/null 2>&1; then
  # Tracked files only; -I skips binary files.
  hits=$(git grep -n -I -E -e "$pattern" -- . ":(exclude)$self" || true)
else
  # A source tree without git (an unpacked archive): every file except build output.
  hits=$(grep -rnIE -e "$pattern" --exclude-dir=.git --exclude-dir='build*' . |
    sed 's|^\./||' | grep -v "^$self:" || true)
fi

if [[ -n "$hits" ]]; then
  echo "check-docs: cite the original source (docs/references.md), not a notes file or a work item:" >&2
  printf '%s\n' "$hits" >&2
  exit 1
fi

# Every public header the README, the docs and the examples name must exist: a header that moved
# (e.g. into its module's folder) leaves readers with an #include that does not compile.
missing=""
while IFS=: read -r file line header; do
  [[ -f "include/$header" ]] || missing+="$file:$line: $header is not under include/"$'\n'
done < <(grep -rnoE 'calligraphy/[a-z0-9_/]+\.hpp' README.md docs examples --include='*.md' --include='*.cpp' \
           --include='*.py' || true)
if [[ -n "$missing" ]]; then
  echo "check-docs: the docs name public headers that do not exist:" >&2
  printf '%s' "$missing" >&2
  exit 1
fi
echo "check-docs: ok"
