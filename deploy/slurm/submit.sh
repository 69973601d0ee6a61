#!/usr/bin/env bash
# Submits a sharded mirrorbox sweep to Slurm: a job array of SHARDS tasks, at most CONCURRENT
# at once, then the merge as a job that starts when every task succeeded.
#   deploy/slurm/submit.sh SHARDS CONCURRENT SWEEP_DIR [sweep arguments...]
# e.g. deploy/slurm/submit.sh 4 2 /shared/runs/box scenes/mirror_box.json --methods auxiliary
# or, an experiment of the registry: SWEEP_COMMAND=experiment deploy/slurm/submit.sh 4 2 DIR table1
# Prints the array's and the merge's job ids. MIRRORBOX and SWEEP_COMMAND pass through.
set -euo pipefail
here=$(cd "$(dirname "$0")" && pwd)
if [ $# -lt 3 ]; then
  echo "usage: deploy/slurm/submit.sh SHARDS CONCURRENT SWEEP_DIR [sweep arguments...]" >&2
  exit 2
fi
shards=$1 concurrent=$2
mkdir -p "$3"
SWEEP_DIR=$(cd "$3" && pwd)
shift 3
case "$shards$concurrent" in
  *[!0-9]*) echo "submit: SHARDS and CONCURRENT must be whole numbers" >&2; exit 2 ;;
esac
if [ "$shards" -lt 1 ] || [ "$concurrent" -lt 1 ]; then
  echo "submit: SHARDS and CONCURRENT must be at least 1" >&2
  exit 2
fi
export SWEEP_DIR SWEEP_ARGS="$*"
array=$(sbatch --parsable --export=ALL --array="0-$((shards - 1))%$concurrent" \
  --output="$SWEEP_DIR/sweep-%A_%a.out" "$here/sweep.sbatch")
merge=$(sbatch --parsable --export=ALL --dependency="afterok:${array%%;*}" \
  --output="$SWEEP_DIR/merge-%j.out" "$here/merge.sbatch")
echo "array $array, merge $merge"
