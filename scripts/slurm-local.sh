#!/usr/bin/env bash
# A one-node Slurm on this machine, for the end-to-end test of sharded sweeps (issue 20):
#   scripts/slurm-local.sh install    apt-get slurm-wlm and munge when missing (root); exits 1
#                                     naming them when they cannot be installed, or when not
#                                     root (the local Slurm needs it), unless MIRRORBOX_TEST_SKIP
#                                     names `slurm` (then a warning, exit 0)
#   scripts/slurm-local.sh start DIR  write DIR/slurm.conf, start munged, slurmctld and slurmd
#                                     (state and logs in DIR); prints `export SLURM_CONF=...`
#   scripts/slurm-local.sh stop DIR   stop the daemons started with DIR
# Needs root (the daemons run as root, munged as the munge user). Debian 12: Slurm 22.05.
# apt-get runs through scripts/lib/apt.sh: it waits for the package system's locks, at most
# MIRRORBOX_APT_LOCK_TIMEOUT seconds (default 600), and names the process holding them.
set -euo pipefail
cmd=${1:-}
dir=${2:-}
here="$(cd "$(dirname "$0")" && pwd)"
APT_LOG_PREFIX=slurm-local
# shellcheck source=scripts/lib/skip.sh
. "$here/lib/skip.sh"
# shellcheck source=scripts/lib/apt.sh
. "$here/lib/apt.sh"

slurm_missing() {
  if ! command -v slurmctld >/dev/null || ! command -v slurmd >/dev/null; then echo slurm-wlm; fi
  command -v munged >/dev/null || echo munge
}

# Installs slurm-wlm and munge when missing (progress on stderr: `start`'s stdout is eval'd).
# False, with $why set, when they are still missing afterwards or this is not root.
why=""
install_slurm() {
  local missing rc
  missing=$(slurm_missing | paste -sd' ')
  if [ "$(id -u)" -ne 0 ]; then
    why="the local Slurm needs root (its daemons run as root), and this is uid $(id -u)${missing:+; missing too: $missing}: run as root"
    return 1
  fi
  if [ -z "$missing" ]; then
    echo "slurm-local: slurm-wlm and munge present; nothing to install." >&2
    return 0
  fi
  echo "slurm-local: installing $missing with apt-get..." >&2
  rc=0
  apt_get -qq update >/dev/null || rc=$?
  if [ "$rc" -eq "$APT_LOCK_TIMED_OUT" ]; then
    why=$APT_ERROR
    return 1
  elif [ "$rc" -ne 0 ]; then
    echo "slurm-local: warning: $APT_ERROR; installing from the package lists already here." >&2
  fi
  rc=0
  # shellcheck disable=SC2086 # $missing: one or two package names
  apt_get install -y -qq --no-install-recommends $missing >/dev/null || rc=$?
  missing=$(slurm_missing | paste -sd' ')
  if [ -n "$missing" ]; then
    why="not installed: $missing (${APT_ERROR:-apt-get reported success, but slurmctld, slurmd or munged is still not on PATH})"
    return 1
  fi
  echo "slurm-local: installed slurm-wlm and munge." >&2
}

install() {
  skip_check_list slurm-local
  install_slurm && return 0
  if skip_allowed slurm; then
    echo "slurm-local: warning: $why. MIRRORBOX_TEST_SKIP names slurm, so the Slurm test will skip." >&2
    return 0
  fi
  echo "slurm-local: error: $why. To go without the local Slurm test instead: MIRRORBOX_TEST_SKIP=slurm." >&2
  exit 1
}

need_dir() {
  if [ -z "$dir" ]; then
    echo "slurm-local: $cmd needs a state folder: scripts/slurm-local.sh $cmd DIR" >&2
    exit 2
  fi
  mkdir -p "$dir"
  dir=$(cd "$dir" && pwd)
}

start() {
  if ! install_slurm; then
    echo "slurm-local: cannot start: $why." >&2
    exit 1
  fi
  need_dir
  mkdir -p "$dir/ctld" "$dir/d" /run/munge
  chown munge:munge /run/munge
  chmod 0755 /run/munge
  if [ ! -s /etc/munge/munge.key ]; then
    dd if=/dev/urandom of=/etc/munge/munge.key bs=1 count=1024 status=none
    chown munge:munge /etc/munge/munge.key
    chmod 0400 /etc/munge/munge.key
  fi
  if ! { [ -s /run/munge/munged.pid ] && kill -0 "$(cat /run/munge/munged.pid)" 2>/dev/null; }; then
    runuser -u munge -- /usr/sbin/munged
    touch "$dir/munged.ours"
  fi
  local host
  host=$(hostname -s)
  cat >"$dir/slurm.conf" <<CONF
ClusterName=mirrorbox
SlurmctldHost=$host(127.0.0.1)
SlurmUser=root
SlurmdUser=root
AuthType=auth/munge
StateSaveLocation=$dir/ctld
SlurmdSpoolDir=$dir/d
SlurmctldPidFile=$dir/slurmctld.pid
SlurmdPidFile=$dir/slurmd.pid
SlurmctldLogFile=$dir/slurmctld.log
SlurmdLogFile=$dir/slurmd.log
SlurmctldPort=6817
SlurmdPort=6818
ProctrackType=proctrack/pgid
TaskPlugin=task/none
SelectType=select/cons_tres
SelectTypeParameters=CR_Core
SchedulerType=sched/backfill
MpiDefault=none
ReturnToService=2
JobCompType=jobcomp/none
AccountingStorageType=accounting_storage/none
NodeName=$host NodeAddr=127.0.0.1 CPUs=$(nproc) State=UNKNOWN
PartitionName=local Nodes=$host Default=YES MaxTime=INFINITE State=UP
CONF
  export SLURM_CONF="$dir/slurm.conf"
  /usr/sbin/slurmctld -f "$SLURM_CONF"
  /usr/sbin/slurmd -f "$SLURM_CONF"
  # Wait until the node takes jobs.
  for _ in $(seq 1 60); do
    if sinfo -h -o '%T' 2>/dev/null | grep -qE '^(idle|mixed|allocated)'; then
      echo "export SLURM_CONF=$SLURM_CONF"
      return 0
    fi
    sleep 1
  done
  echo "slurm-local: the node did not come up; see $dir/slurmctld.log and $dir/slurmd.log" >&2
  sinfo >&2 || true
  exit 1
}

stop() {
  need_dir
  pids=()
  for d in slurmd slurmctld; do
    if [ -s "$dir/$d.pid" ]; then
      pids+=("$(cat "$dir/$d.pid")")
    fi
  done
  if [ -e "$dir/munged.ours" ] && [ -s /run/munge/munged.pid ]; then
    pids+=("$(cat /run/munge/munged.pid)")
    rm -f "$dir/munged.ours"
  fi
  [ ${#pids[@]} -eq 0 ] && return 0
  kill "${pids[@]}" 2>/dev/null || true
  # Wait until they are gone (a later start reuses their ports).
  for _ in $(seq 1 50); do
    kill -0 "${pids[@]}" 2>/dev/null || return 0
    sleep 0.2
  done
  kill -9 "${pids[@]}" 2>/dev/null || true
}

case "$cmd" in
  install) install ;;
  start) start ;;
  stop) stop ;;
  *)
    echo "usage: scripts/slurm-local.sh install | start DIR | stop DIR" >&2
    exit 2
    ;;
esac
