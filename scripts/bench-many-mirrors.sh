#!/usr/bin/env bash
# shellcheck disable=SC2086  # the lists (--n, --variants, --commands) are split into words on purpose
# Many mirrors at linear cost (issue 51): how `check`, `trace` and `render` scale with the
# number of mirrors. Seed 002 names many mirrors as the mirror camera's limit (a disco ball,
# a mirror facade: thousands of facets); measured before this script, 20 000 facets loaded,
# checked and traced in 0.1-0.3 s, but 20 000 facets sharing one normal map took `check`
# 18.6 s and 3.85 GB (the map decoded once per mirror), and 20 000 coincident mirrors took
# the BVH build 33 s.
#
# For every N and variant, scripts/make_mirror_mosaic.py writes a scene into a temporary
# folder (not timed); the variants:
#   wall             a facade of N facets, each tilted by up to 3 degrees
#   wall+normal-map  the same, every facet with the bundled scenes/textures/hammered.png
#   sphere           a disco ball of N facets in a room
#   coincident       N copies of one wall facet at the same place (the degenerate case)
# Then each command, under /usr/bin/time -f '%e %M' (wall seconds, peak resident KB) and
# `timeout` (--timeout, default 120 s):
#   check     BIN check SCENE
#   trace     BIN trace SCENE -o T.exr --width 160 --height 90
#   naive     BIN render SCENE --method naive -o R.png --width 160 --height 90
#   unrolled  BIN render SCENE --method unrolled --depth 4 -o R.png --width 160 --height 90
# Each measurement is repeated --reps times (default 3), round-robin: repetition r runs
# every N, variant and command once before repetition r+1 starts, so that drift of a shared
# machine falls on all alike. A command that fails (a refusal, a crash, the timeout) is
# recorded with its exit code and its first error line and the script goes on; a command
# that timed out is not run again for that variant at that N or any larger N (recorded as
# skipped), so that one slow method does not take the whole run.
#
# Writes OUT/raw.jsonl (one JSON object a line: a "meta" line, one "scene" line per scene,
# one "run" line per measurement; the file is rewritten, not appended to), then
# scripts/many_mirrors_report.py writes OUT/report.md and OUT/report.svg from it.
#
# The binary is not built here: build it first (cargo build --release --locked -p
# mirrorbox); the record names the commit (seven hex digits, "-dirty" with changes) and the binary's
# modification time.
#
# Usage: scripts/bench-many-mirrors.sh [--n "100 1000 10000 20000"] [--reps 3]
#          [--timeout 120] [--variants "wall wall+normal-map sphere coincident"]
#          [--commands "check trace naive unrolled"] [--out reports/many_mirrors]
#          [--bin target/release/mirrorbox]
set -euo pipefail
cd "$(dirname "$0")/.."

ns="100 1000 10000 20000"
reps=3
cap=120
variants="wall wall+normal-map sphere coincident"
commands="check trace naive unrolled"
out=reports/many_mirrors
bin=target/release/mirrorbox
usage() { sed -n '/^# Usage:/,/^set -euo/p' "$0" | sed '$d; s/^# \{0,1\}//' >&2; exit 2; }
while [ $# -gt 0 ]; do
  [ $# -ge 2 ] || usage
  case "$1" in
    --n) ns=$2 ;;
    --reps) reps=$2 ;;
    --timeout) cap=$2 ;;
    --variants) variants=$2 ;;
    --commands) commands=$2 ;;
    --out) out=$2 ;;
    --bin) bin=$2 ;;
    *) usage ;;
  esac
  shift 2
done
case "$reps" in ''|*[!0-9]*|0) echo "--reps must be a positive integer, got '$reps'" >&2; exit 2 ;; esac
case "$cap" in ''|*[!0-9]*|0) echo "--timeout must be a positive integer (seconds), got '$cap'" >&2; exit 2 ;; esac
for n in $ns; do
  case "$n" in ''|*[!0-9]*) echo "--n: '$n' is not a positive integer" >&2; exit 2 ;; esac
done
for v in $variants; do
  case "$v" in wall|wall+normal-map|sphere|coincident) ;;
    *) echo "--variants: unknown variant '$v' (wall, wall+normal-map, sphere, coincident)" >&2; exit 2 ;; esac
done
for c in $commands; do
  case "$c" in check|trace|naive|unrolled) ;;
    *) echo "--commands: unknown command '$c' (check, trace, naive, unrolled)" >&2; exit 2 ;; esac
done
if [ ! -x "$bin" ]; then
  echo "no binary at $bin: build it first (cargo build --release --locked -p mirrorbox)" >&2
  exit 2
fi
# The N values in increasing order (the timeout skip below relies on it).
ns=$(printf '%s\n' $ns | sort -n -u | tr '\n' ' ')

mkdir -p "$out"
raw="$out/raw.jsonl"
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
mkdir -p "$work/scenes" "$work/out"

# One JSON line from KEY VALUE pairs; a value given as json:TEXT is written as JSON TEXT
# (numbers, null, lists), any other as a string.
record() {
  python3 -c '
import json, sys
a = sys.argv[1:]
d = {}
for k, v in zip(a[::2], a[1::2]):
    d[k] = json.loads(v[5:]) if v.startswith("json:") else v
print(json.dumps(d))' "$@" >> "$raw"
}

gen_args() {  # the generator's arguments of variant $1 at N $2
  case "$1" in
    wall) echo "--shape wall --count $2" ;;
    wall+normal-map) echo "--shape wall --count $2 --normal-map scenes/textures/hammered.png" ;;
    sphere) echo "--shape sphere --count $2" ;;
    coincident) echo "--shape wall --count $2 --coincident" ;;
  esac
}

cmd_line() {  # the command $1 on scene $2, as words
  case "$1" in
    check) echo "$bin check $2" ;;
    trace) echo "$bin trace $2 -o $work/out/T.exr --width 160 --height 90" ;;
    naive) echo "$bin render $2 --method naive -o $work/out/R.png --width 160 --height 90" ;;
    unrolled) echo "$bin render $2 --method unrolled --depth 4 -o $work/out/R.png --width 160 --height 90" ;;
  esac
}

cpu=$(grep -m1 '^model name' /proc/cpuinfo | cut -d: -f2- | sed 's/^ *//' || true)
# Before the record is emptied: emptying a committed raw.jsonl would itself make the tree dirty.
# The first seven hex digits (git's own abbreviation grows with the repository), "-dirty" with
# changes to tracked files.
commit=$(git rev-parse HEAD 2>/dev/null | cut -c1-7 || true)
[ -n "$commit" ] || commit=unknown
if [ "$commit" != unknown ] && ! git diff --quiet HEAD 2>/dev/null; then
  commit="$commit-dirty"
fi
: > "$raw"
record kind meta date "$(date -u +%Y-%m-%dT%H:%M:%SZ)" cpu "${cpu:-unknown}" \
  cores "json:$(nproc)" cpus_in_cpuinfo "json:$(grep -c '^processor' /proc/cpuinfo || true)" \
  commit "$commit" \
  binary "$bin" binary_mtime "$(date -u -r "$bin" +%Y-%m-%dT%H:%M:%SZ)" \
  timeout_s "json:$cap" reps "json:$reps" \
  ns "json:[$(echo $ns | tr ' ' ',')]" \
  variants "json:$(printf '%s\n' $variants | python3 -c 'import json,sys; print(json.dumps(sys.stdin.read().split()))')" \
  commands "json:$(for c in $commands; do cmd_line "$c" SCENE; done | sed "s#$work/out/##g" |
    python3 -c 'import json,sys; print(json.dumps(sys.stdin.read().splitlines()))')" \
  command_names "json:$(printf '%s\n' $commands | python3 -c 'import json,sys; print(json.dumps(sys.stdin.read().split()))')" \
  generator "json:$(for v in $variants; do echo "$v: scripts/make_mirror_mosaic.py $(gen_args "$v" N) -o SCENE"; done |
    python3 -c 'import json,sys; print(json.dumps(sys.stdin.read().splitlines()))')"

# The scenes, written once (not timed).
for n in $ns; do
  for v in $variants; do
    scene="$work/scenes/$v-$n.json"
    rc=0
    # shellcheck disable=SC2046
    python3 scripts/make_mirror_mosaic.py $(gen_args "$v" "$n") -o "$scene" 2> "$work/gen.err" || rc=$?
    if [ "$rc" = 0 ]; then
      record kind scene variant "$v" n "json:$n" exit json:0 bytes "json:$(stat -c %s "$scene")"
    else
      record kind scene variant "$v" n "json:$n" exit "json:$rc" error "$(grep -m1 . "$work/gen.err" || true)"
    fi
  done
done

first_error() {  # the first line of stderr that says error, else its first non-empty line
  grep -m1 -i 'error' "$1" || grep -m1 . "$1" || true
}

for rep in $(seq "$reps"); do
  for n in $ns; do
    for v in $variants; do
      scene="$work/scenes/$v-$n.json"
      for c in $commands; do
        echo "rep $rep/$reps: N=$n $v $c" >&2
        if [ ! -f "$scene" ]; then
          record kind run variant "$v" n "json:$n" command "$c" rep "json:$rep" skipped "no scene (the generator failed)"
          continue
        fi
        # Skipped only at the N it timed out at and above (a later repetition still runs the
        # smaller N).
        if [ -f "$work/timedout.$v.$c" ] && [ "$n" -ge "$(cat "$work/timedout_n.$v.$c")" ]; then
          record kind run variant "$v" n "json:$n" command "$c" rep "json:$rep" skipped "$(cat "$work/timedout.$v.$c")"
          continue
        fi
        rm -f "$work"/out/*
        rc=0
        # shellcheck disable=SC2046
        /usr/bin/time -f '%e %M' -o "$work/time" timeout -k 10 "$cap" $(cmd_line "$c" "$scene") \
          > "$work/stdout" 2> "$work/stderr" || rc=$?
        # GNU time writes "Command exited with non-zero status N" (or "... terminated by
        # signal N") before the format's line when the command fails: the last line is ours.
        read -r secs rss < <(tail -n 1 "$work/time" 2>/dev/null) || true
        [[ ${secs:-} =~ ^[0-9]+(\.[0-9]+)?$ ]] || secs=""
        [[ ${rss:-} =~ ^[0-9]+$ ]] || rss=""
        err=null
        # timeout exits 124 when it stopped the command, 137 when it had to kill it; 137
        # before the limit is another SIGKILL (the kernel's out-of-memory killer).
        if [ "$rc" = 124 ] || { [ "$rc" = 137 ] && [ "${secs%.*}" -ge "$cap" ] 2>/dev/null; }; then
          err="timed out after $cap s"
          if [ ! -f "$work/timedout.$v.$c" ] || [ "$n" -lt "$(cat "$work/timedout_n.$v.$c")" ]; then
            echo "timed out at N=$n in rep $rep" > "$work/timedout.$v.$c"
            echo "$n" > "$work/timedout_n.$v.$c"
          fi
        elif [ "$rc" -gt 128 ]; then
          err="killed by signal $((rc - 128))"
          [ "$rc" != 137 ] || err="$err (SIGKILL: out of memory?)"
        elif [ "$rc" != 0 ]; then
          err=$(first_error "$work/stderr")
          [ -n "$err" ] || err="exit $rc, nothing on stderr"
        fi
        if [ "$err" = null ]; then
          record kind run variant "$v" n "json:$n" command "$c" rep "json:$rep" exit "json:$rc" \
            seconds "json:${secs:-null}" max_rss_kb "json:${rss:-null}"
        else
          record kind run variant "$v" n "json:$n" command "$c" rep "json:$rep" exit "json:$rc" \
            seconds "json:${secs:-null}" max_rss_kb "json:${rss:-null}" error "$err"
        fi
      done
    done
  done
done

python3 scripts/many_mirrors_report.py "$raw" "$out"
