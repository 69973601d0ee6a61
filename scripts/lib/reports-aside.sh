# shellcheck shell=bash
# A measuring script replaces a committed report folder whole, or not at all.
#
# set_reports_aside DIR: DIR (the committed reports, if any) moves to DIR.previous and an empty
# DIR takes its place, for the script to fill under its own name (the commands it records
# name DIR, so it cannot be filled elsewhere and moved in). Until `keep_new_reports` is called,
# any end of the script (an error under `set -e`, Ctrl-C, a kill by TERM) removes the
# half-made DIR and puts DIR.previous back: a failed run leaves the reports as they were.
# Sourced by scripts/measure-advise.sh and scripts/measure-table1-runs.sh; the EXIT trap is
# this file's, so a script that needs its own clean-up adds it with `on_exit COMMAND`.
reports_aside_dir=
reports_aside_extra=
set_reports_aside() {
  reports_aside_dir=$1
  # A DIR.previous left by a run killed outright (SIGKILL, no trap ran) holds the committed
  # reports, and DIR that run's half: put them back first, never delete them.
  if [ -e "$1.previous" ]; then
    rm -rf "$1"
    mv "$1.previous" "$1"
    echo "$1: an earlier run was killed while measuring; its committed reports are back" >&2
  fi
  if [ -e "$1" ]; then
    mv "$1" "$1.previous"
  fi
  mkdir -p "$1"
  trap restore_reports EXIT # bash runs it on INT and TERM too (tests/scripts.rs)
}
# on_exit COMMAND: COMMAND run at the script's end as well (after the reports are settled).
on_exit() {
  reports_aside_extra="$reports_aside_extra${reports_aside_extra:+; }$1"
}
keep_new_reports() {
  rm -rf "$reports_aside_dir.previous"
  reports_aside_dir=
}
restore_reports() {
  local status=$?
  if [ -n "$reports_aside_dir" ]; then
    rm -rf "$reports_aside_dir"
    if [ -e "$reports_aside_dir.previous" ]; then
      mv "$reports_aside_dir.previous" "$reports_aside_dir"
      echo "$reports_aside_dir: the run did not finish; the earlier reports are back" >&2
    else
      echo "$reports_aside_dir: the run did not finish; its partial output is removed" >&2
    fi
  fi
  eval "$reports_aside_extra"
  return "$status"
}
