# shellcheck shell=bash
# A measuring script replaces a committed report folder whole, or not at all.
#
# set_reports_aside DIR: DIR (the committed reports, if any) moves to DIR.previous and an empty
# DIR takes its place, for the script to fill under its own name (the commands it records
# name DIR, so it cannot be filled elsewhere and moved in). Until `keep_new_reports` is called,
# any end of the script (an error under `set -e`, Ctrl-C, a kill by TERM) removes the
# half-made DIR and puts DIR.previous back: a failed run leaves the reports as they were.
#
# The states a run killed outright (SIGKILL: no trap runs) can leave, each settled by the next
# run before anything else:
#   DIR.previous      the committed reports, DIR the killed run's half: put back;
#   DIR.none          there were none, DIR is the killed run's half: removed;
#   DIR.discard       the reports a finished run replaced, killed while deleting: deleted.
# One run at a time: DIR.lock (flock) is held for the script's life; a second is refused.
# Sourced by scripts/measure-advise.sh and scripts/measure-table1-runs.sh; the EXIT trap is
# this file's, so a script that needs its own clean-up adds it with `on_exit COMMAND`.
reports_aside_dir=
reports_aside_extra=
set_reports_aside() {
  exec 9>"$1.lock"
  if ! flock -n 9; then
    echo "$1: another run is measuring into it ($1.lock is held)" >&2
    exit 1
  fi
  rm -rf "$1.discard"
  if [ -e "$1.previous" ]; then
    rm -rf "$1"
    mv "$1.previous" "$1"
    rm -f "$1.none"
    echo "$1: an earlier run was killed while measuring; its committed reports are back" >&2
  elif [ -e "$1.none" ]; then
    rm -rf "$1"
    rm -f "$1.none"
    echo "$1: an earlier first run was killed while measuring; its half is removed" >&2
  fi
  reports_aside_dir=$1
  if [ -e "$1" ]; then
    mv "$1" "$1.previous"
  else
    touch "$1.none"
  fi
  mkdir -p "$1"
  trap restore_reports EXIT # bash runs it on INT and TERM too (tests/scripts.rs)
}
# on_exit COMMAND: COMMAND run at the script's end as well (after the reports are settled).
on_exit() {
  reports_aside_extra="$reports_aside_extra${reports_aside_extra:+; }$1"
}
# carry_over_reports NAME...: the committed DIR/NAME entries (glob patterns; runs the script
# does not make, such as ones made by hand) carried from DIR.previous into the new DIR, before
# `keep_new_reports`. An entry the new run made itself is not overwritten.
carry_over_reports() {
  local d=$reports_aside_dir pattern kept
  [ -e "$d.previous" ] || return 0
  for pattern in "$@"; do
    for kept in "$d.previous"/$pattern; do
      if [ -e "$kept" ] && [ ! -e "$d/${kept##*/}" ]; then cp -r "$kept" "$d/"; fi
    done
  done
}
keep_new_reports() {
  local d=$reports_aside_dir
  reports_aside_dir=
  rm -f "$d.none"
  # Renamed first (one step), deleted after: a kill while deleting leaves DIR.discard, never
  # a DIR.previous that a later run would put back over these reports.
  if [ -e "$d.previous" ]; then
    mv "$d.previous" "$d.discard"
    rm -rf "$d.discard"
  fi
}
restore_reports() {
  local status=$?
  if [ -n "$reports_aside_dir" ]; then
    local d=$reports_aside_dir
    rm -rf "$d"
    if [ -e "$d.previous" ]; then
      mv "$d.previous" "$d"
      echo "$d: the run did not finish; the earlier reports are back" >&2
    else
      echo "$d: the run did not finish; its partial output is removed" >&2
    fi
    rm -f "$d.none"
  fi
  eval "$reports_aside_extra"
  return "$status"
}
