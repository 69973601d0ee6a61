#!/usr/bin/env bash
# Issue 57: what the device tool sends to a lent GPU machine is the checkout's tracked and
# untracked-not-ignored files, at most 64 MiB with the carried .gpu/ and .gl/ (or .bench/); the
# committed reports alone are larger. scripts/gpu-measure.sh and scripts/bench-tracer-device.sh
# need neither the reports (they write new files under reports/) nor docs/ (2.4 MB, which
# .bench/'s 62 MB cannot spare), so for the length of the lease both leave git's index and are
# ignored; nothing in the working tree is touched. Commit nothing between light and restore:
# the index then holds the deletions of both folders.
#   scripts/gpu-tree.sh light     before the device calls: reports/ and docs/ untracked, ignored
#   scripts/gpu-tree.sh restore   after them: the index as HEAD has it, both tracked again
#   scripts/gpu-tree.sh size      what would travel, in bytes (tracked + untracked, not ignored)
set -euo pipefail
cd "$(dirname "$0")/.."
exclude=$(git rev-parse --git-path info/exclude)
case ${1:-} in
light)
  if grep -qx '/reports/' "$exclude" 2>/dev/null; then
    echo "gpu-tree.sh: already light (reports/ is excluded); run scripts/gpu-tree.sh restore" >&2
    exit 2
  fi
  if ! git diff --cached --quiet; then
    echo "gpu-tree.sh: the index holds staged changes; commit or unstage them first" >&2
    exit 2
  fi
  mkdir -p "$(dirname "$exclude")"
  for p in reports docs; do
    git rm -r --cached -q "$p"
    grep -qx "/$p/" "$exclude" 2>/dev/null || printf '/%s/\n' "$p" >>"$exclude"
  done
  ;;
restore)
  # The index first: it is what matters, and needs no exclude file.
  git reset -q
  if [ -f "$exclude" ]; then
    sed -i '/^\/reports\/$/d; /^\/docs\/$/d' "$exclude"
  fi
  ;;
size) ;;
*)
  echo "usage: scripts/gpu-tree.sh light|restore|size" >&2
  exit 2
  ;;
esac
git ls-files -z --cached --others --exclude-standard | du -cb --files0-from=- 2>/dev/null | tail -n 1
