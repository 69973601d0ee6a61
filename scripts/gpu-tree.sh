#!/usr/bin/env bash
# Issue 57: what the device tool sends to a lent GPU machine is the checkout's tracked and
# untracked-not-ignored files, at most 64 MiB with the carried .gpu/ and .gl/; the committed
# reports alone are larger. scripts/gpu-measure.sh needs none of them (it writes new folders
# under reports/gpu/), so for the length of the lease the reports leave git's index and are
# ignored; nothing in the working tree is touched.
#   scripts/gpu-tree.sh light     before the device calls: reports/ untracked and ignored
#   scripts/gpu-tree.sh restore   after them: the index as HEAD has it, reports/ tracked again
#   scripts/gpu-tree.sh size      what would travel, in bytes (tracked + untracked, not ignored)
set -euo pipefail
cd "$(dirname "$0")/.."
exclude=.git/info/exclude
case ${1:-} in
light)
  if ! git diff --cached --quiet; then
    echo "gpu-tree.sh: the index holds staged changes; commit or unstage them first" >&2
    exit 2
  fi
  git rm -r --cached -q reports
  grep -qx '/reports/' "$exclude" 2>/dev/null || printf '/reports/\n' >>"$exclude"
  ;;
restore)
  sed -i '/^\/reports\/$/d' "$exclude"
  git reset -q
  ;;
size) ;;
*)
  echo "usage: scripts/gpu-tree.sh light|restore|size" >&2
  exit 2
  ;;
esac
git ls-files -z --cached --others --exclude-standard | du -cb --files0-from=- 2>/dev/null | tail -n 1
