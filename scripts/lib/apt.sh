# shellcheck shell=bash
# apt-get that waits for the package system's locks, bounded, and names who holds them.
# Sourced (never run) by scripts/install-system-deps.sh, scripts/slurm-local.sh and
# tools/mitsuba/setup.sh: every apt-get call of the project goes through `apt_get`.
#
#   apt_get ARGS...   runs `apt-get ARGS...` (through "${APT_SUDO[@]}", empty when root),
#                     after waiting for the four locks below to be free; returns apt-get's
#                     status, or $APT_LOCK_TIMED_OUT (75) when a lock stayed held past the
#                     timeout. $APT_ERROR then holds a one-line reason for the caller's message.
#
# The locks (apt 2.6, Debian 12), all fcntl (F_SETLK) write locks:
#   /var/lib/dpkg/lock-frontend  every frontend's (apt-get install/remove, unattended-upgrades)
#   /var/lib/dpkg/lock           dpkg's own (apt hands it to the dpkg it runs)
#   /var/lib/apt/lists/lock      apt-get update's
#   /var/cache/apt/archives/lock downloads into the package cache (apt-get install)
# apt's own `-o DPkg::Lock::Timeout=N` waits only for the first two (measured with apt 2.6.1:
# `apt-get -o DPkg::Lock::Timeout=30 update` fails at once with "Could not get lock
# /var/lib/apt/lists/lock", and so does an install that downloads while the archives lock is
# held). So apt_get first waits for all four itself, then passes the time left as
# DPkg::Lock::Timeout (a frontend that takes the dpkg locks between our check and apt-get's
# start is waited for by apt), and if apt-get still fails on a lock (the lists or archives
# lock taken in that gap) waits again and retries, all within one deadline.
#
# MIRRORBOX_APT_LOCK_TIMEOUT: the seconds each apt_get call waits at most (default 600; 0: do
# not wait). The holder of a lock is found in the kernel's table of file locks, /proc/locks
# (the lock file's device and inode), and named by its pid and command line (/proc/PID/cmdline).

APT_LOCK_FILES=(/var/lib/dpkg/lock-frontend /var/lib/dpkg/lock /var/lib/apt/lists/lock /var/cache/apt/archives/lock)
APT_LOCK_TIMED_OUT=75
APT_ERROR=""
if ! declare -p APT_SUDO >/dev/null 2>&1; then
  APT_SUDO=()
fi
APT_LOG_PREFIX=${APT_LOG_PREFIX:-apt}

# The timeout in seconds, validated when this file is sourced: a value that is not a whole
# number exits the sourcing script with 2.
APT_LOCK_TIMEOUT=${MIRRORBOX_APT_LOCK_TIMEOUT:-600}
if ! [[ $APT_LOCK_TIMEOUT =~ ^[0-9]+$ ]]; then
  echo "$APT_LOG_PREFIX: MIRRORBOX_APT_LOCK_TIMEOUT='$APT_LOCK_TIMEOUT' is not a number of seconds (a whole number, 0 or more; default 600)." >&2
  exit 2
fi
APT_LOCK_TIMEOUT=$((10#$APT_LOCK_TIMEOUT))

# "pid PID (COMMAND LINE)" for one process, with its parent when that says more (dpkg run by
# apt, a python script run by a service).
apt_describe_pid() {
  local pid=$1 cmd ppid pcmd
  if [ "$pid" -le 0 ] 2>/dev/null; then
    echo "a process outside this PID namespace, or an open-file-description lock (pid $pid in /proc/locks)"
    return
  fi
  if [ ! -d "/proc/$pid" ]; then
    echo "pid $pid (no longer running)"
    return
  fi
  if [ ! -r "/proc/$pid/cmdline" ]; then
    echo "pid $pid (its command line is not readable here)"
    return
  fi
  cmd=$(tr '\0' ' ' <"/proc/$pid/cmdline" 2>/dev/null | sed 's/ *$//')
  [ -n "$cmd" ] || cmd="[$(cat "/proc/$pid/comm" 2>/dev/null)]"
  ppid=$(awk '/^PPid:/ { print $2 }' "/proc/$pid/status" 2>/dev/null)
  if [ -n "$ppid" ] && [ "$ppid" -gt 1 ] && [ -r "/proc/$ppid/cmdline" ]; then
    pcmd=$(tr '\0' ' ' <"/proc/$ppid/cmdline" 2>/dev/null | sed 's/ *$//')
    echo "pid $pid ($cmd), child of pid $ppid ($pcmd)"
  else
    echo "pid $pid ($cmd)"
  fi
}

# The pids holding a lock (granted, not waiting) on the file $1, one a line, from /proc/locks;
# nothing when it is free or does not exist. A line matches on the file's inode and device,
# or, where the device differs (overlay file systems report the lower one), on the inode and
# the pid having the file open.
apt_lock_holders() {
  local file=$1 ino dev major minor
  [ -e "$file" ] && [ -r /proc/locks ] || return 0
  ino=$(stat -L -c %i "$file" 2>/dev/null) || return 0
  dev=$(stat -L -c %d "$file" 2>/dev/null) || return 0
  major=$(printf '%02x' $((((dev >> 8) & 0xfff) | ((dev >> 32) & ~0xfff))))
  minor=$(printf '%02x' $(((dev & 0xff) | ((dev >> 12) & ~0xff))))
  # "1: POSIX  ADVISORY  WRITE 1234 fe:00:379257 0 EOF"; a waiter's line has "->" after "1:".
  awk -v ino="$ino" -v dev="$major:$minor" '
    $2 != "->" {
      n = split($6, id, ":")
      if (n == 3 && id[3] == ino) print $5, ((id[1] ":" id[2]) == dev ? "same" : "other")
    }' /proc/locks | while read -r pid where; do
    if [ "$where" = same ]; then
      echo "$pid"
    elif [ "$pid" -gt 0 ] 2>/dev/null &&
      find "/proc/$pid/fd" -maxdepth 1 -lname "$file" 2>/dev/null | grep -q .; then
      echo "$pid"
    fi
  done | sort -un
}

# "pid PID (COMMAND LINE) holds LOCK, LOCK" for every process holding locks of
# APT_LOCK_FILES, one a line; nothing when they are all free.
apt_held_locks() {
  local f pid
  local -A held=()
  local order=()
  for f in "${APT_LOCK_FILES[@]}"; do
    for pid in $(apt_lock_holders "$f"); do
      [ -n "${held[$pid]:-}" ] || order+=("$pid")
      held[$pid]+="${held[$pid]:+, }$f"
    done
  done
  for pid in "${order[@]}"; do
    echo "$(apt_describe_pid "$pid") holds ${held[$pid]}"
  done
}

# Waits until no lock of APT_LOCK_FILES is held, or until SECONDS reaches $1; says who holds
# what when it starts waiting, when that changes and every 30 s. Returns 1 at the deadline,
# with APT_ERROR naming the holders.
apt_wait_for_locks() {
  local deadline=$1 what=$2 held last="" started=$SECONDS next_note=$((SECONDS + 30))
  local total=$APT_LOCK_TIMEOUT
  while held=$(apt_held_locks) && [ -n "$held" ]; do
    if [ "$SECONDS" -ge "$deadline" ]; then
      APT_ERROR="gave up on 'apt-get $what' after waiting $((SECONDS - started)) s (MIRRORBOX_APT_LOCK_TIMEOUT=$total) for the package system's locks: $(echo "$held" | paste -sd ';' | sed 's/;/; /g') (found in /proc/locks). Wait for that process to finish (unattended-upgrades on a fresh machine: \`systemctl stop unattended-upgrades\` or wait), then run this again; MIRRORBOX_APT_LOCK_TIMEOUT=SECONDS waits longer"
      return 1
    fi
    if [ "$held" != "$last" ] || [ "$SECONDS" -ge "$next_note" ]; then
      echo "$APT_LOG_PREFIX: waiting for the package system's locks before 'apt-get $what' ($((SECONDS - started)) s of at most $total s, MIRRORBOX_APT_LOCK_TIMEOUT; holders found in /proc/locks):" >&2
      local line
      while read -r line; do echo "$APT_LOG_PREFIX:   $line" >&2; done <<<"$held"
      last=$held
      next_note=$((SECONDS + 30))
    fi
    sleep 1
  done
  if [ -n "$last" ]; then
    echo "$APT_LOG_PREFIX: the locks are free after $((SECONDS - started)) s; running 'apt-get $what'." >&2
  fi
  return 0
}

# apt-get ARGS..., waiting for the locks (see the top of this file). apt-get's stdout is the
# caller's; its stderr is shown once it is done.
apt_get() {
  local timeout=$APT_LOCK_TIMEOUT deadline left rc err what="$*" lockmsg note_at=0 held pid
  deadline=$((SECONDS + timeout))
  APT_ERROR=""
  err=$(mktemp)
  while :; do
    if ! apt_wait_for_locks "$deadline" "$what"; then
      rm -f "$err"
      echo "$APT_LOG_PREFIX: $APT_ERROR." >&2
      return "$APT_LOCK_TIMED_OUT"
    fi
    left=$((deadline - SECONDS))
    [ "$left" -ge 0 ] || left=0
    rc=0
    "${APT_SUDO[@]}" env DEBIAN_FRONTEND=noninteractive apt-get -o "DPkg::Lock::Timeout=$left" "$@" 2>"$err" || rc=$?
    if [ "$rc" -ne 0 ] && lockmsg=$(grep -m1 'Could not get lock' "$err"); then
      if [ "$SECONDS" -lt "$deadline" ]; then
        if [ "$SECONDS" -ge "$note_at" ]; then
          echo "$APT_LOG_PREFIX: 'apt-get $what' found a lock taken after the check (${lockmsg#E: }); waiting again, up to $((deadline - SECONDS)) s more." >&2
          note_at=$((SECONDS + 30))
        fi
        sleep 1
        continue
      fi
      held=$(apt_held_locks)
      if [ -n "$held" ]; then
        held="$held (found in /proc/locks)"
      else
        # apt's own words name the pid ("It is held by process 1234 (apt-get)").
        pid=$(echo "$lockmsg" | sed -n 's/.*held by process \([0-9][0-9]*\).*/\1/p')
        held="apt-get said: ${lockmsg#E: }${pid:+; that is $(apt_describe_pid "$pid")}"
      fi
      APT_ERROR="gave up on 'apt-get $what' after $timeout s (MIRRORBOX_APT_LOCK_TIMEOUT): $held. Wait for that process to finish, then run this again; MIRRORBOX_APT_LOCK_TIMEOUT=SECONDS waits longer"
      rm -f "$err"
      echo "$APT_LOG_PREFIX: $APT_ERROR." >&2
      return "$APT_LOCK_TIMED_OUT"
    fi
    cat "$err" >&2
    rm -f "$err"
    if [ "$rc" -ne 0 ]; then
      APT_ERROR="'apt-get $what' exited $rc (its messages are above)"
    fi
    return "$rc"
  done
}
