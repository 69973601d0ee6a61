#!/usr/bin/env bash
# Installs what mirrorbox and its tests need from the system, saying what it does.
#   - Mesa >= 25.0.7: its software Vulkan driver (lavapipe, mesa-vulkan-drivers) with the
#     Vulkan loader (libvulkan1), and its EGL/GL drivers as the fallback backend (libegl1: the
#     libEGL.so.1 wgpu loads; libegl-mesa0: Mesa's EGL vendor library; libgl1-mesa-dri:
#     llvmpipe, swrast_dri.so). Older Mesa is *upgraded*, not only a missing one installed:
#     Debian 12's own Mesa 22.3.6 lavapipe keeps the memory of every executed render pass
#     (a 32x18 render of mirror_room with `auxiliary --n 2` peaks at 18 GB there, 235 MB on
#     Mesa 25). On Debian 12 (bookworm) Mesa 25 comes from the official backports suite,
#     which is added as /etc/apt/sources.list.d/bookworm-backports.sources (deb822) when no
#     apt source names it yet. Elsewhere the script says which version is needed.
#   - for `mirrorbox view`: the X11 client libraries winit loads at run time (libx11-6,
#     libx11-xcb1, libxcursor1, libxrandr2, libxi6, libxkbcommon-x11-0), Xvfb (xvfb,
#     xauth for xvfb-run), the virtual display its tests and screenshots run on, and xdotool,
#     with which the tests type and drag in it.
#   - GNU time (the main job's peak memory), chromium-headless-shell (the reports test opens
#     every HTML report in it) and assimp-testmodels (the OBJ corpus test's public assets).
# Uses apt-get when run as root (or through sudo when available), through scripts/lib/apt.sh:
# each call waits for the package system's locks, at most MIRRORBOX_APT_LOCK_TIMEOUT seconds
# (default 600), and names the process holding them when it gives up.
# Idempotent: does nothing when everything is present and current.
# Exits 0 when everything the tests need is there; otherwise 1, naming what is missing and
# why (not root, apt-get's error, a lock held too long). A component named in
# MIRRORBOX_TEST_SKIP (scripts/lib/skip.sh: corpus, xvfb, xdotool, chromium, ...) is not
# needed: what is missing of it is a warning. Exit 2: a bad MIRRORBOX_TEST_SKIP or
# MIRRORBOX_APT_LOCK_TIMEOUT.
set -uo pipefail
here="$(cd "$(dirname "$0")" && pwd)"
APT_LOG_PREFIX=install-system-deps
# shellcheck source=scripts/lib/skip.sh
. "$here/lib/skip.sh"
skip_check_list install-system-deps
# shellcheck source=scripts/lib/apt.sh
. "$here/lib/apt.sh"

MESA_MIN=25.0.7
MESA_PACKAGES=(mesa-vulkan-drivers libvulkan1 libegl1 libegl-mesa0 libgl1-mesa-dri)
# The other packages, in the order they are named.
PACKAGES=(libx11-6 libx11-xcb1 libxcursor1 libxrandr2 libxi6 libxkbcommon-x11-0 xvfb xauth
  xdotool time chromium-headless-shell assimp-testmodels nodejs npm)

ldconfig_bin=$(command -v ldconfig || echo /sbin/ldconfig)
# (grep reads all of ldconfig's output: `grep -q` would end the pipe early, and pipefail
# would turn ldconfig's SIGPIPE into "missing".)
have_lib() { "$ldconfig_bin" -p 2>/dev/null | grep "$1" >/dev/null; }
# The installed version of a Debian package, empty when it is not installed.
deb_version() { dpkg-query -W -f='${Status} ${Version}\n' "$1" 2>/dev/null | awk '$3 == "installed" { print $4 }'; }
# True when the Debian version $1 is at least $2.
version_at_least() { dpkg --compare-versions "$1" ge "$2"; }
is_bookworm() { [ -r /etc/os-release ] && (. /etc/os-release && [ "${VERSION_CODENAME:-}" = bookworm ]); }

# Whether a package of PACKAGES is present (what the program or the tests look for).
present() {
  case $1 in
    libx11-6) have_lib 'libX11\.so\.6' ;;
    libx11-xcb1) have_lib 'libX11-xcb\.so\.1' ;;
    libxcursor1) have_lib 'libXcursor\.so\.1' ;;
    libxrandr2) have_lib 'libXrandr\.so\.2' ;;
    libxi6) have_lib 'libXi\.so\.6' ;;
    libxkbcommon-x11-0) have_lib 'libxkbcommon-x11\.so\.0' ;;
    xvfb) command -v Xvfb >/dev/null 2>&1 ;;
    xauth) command -v xauth >/dev/null 2>&1 ;;
    xdotool) command -v xdotool >/dev/null 2>&1 ;;
    time) [ -x /usr/bin/time ] ;;
    chromium-headless-shell) command -v chromium-headless-shell >/dev/null 2>&1 ;;
    assimp-testmodels) [ -d /usr/share/assimp/models/OBJ ] ;;
    nodejs) command -v node >/dev/null 2>&1 ;;
    npm) command -v npm >/dev/null 2>&1 ;;
    *) return 1 ;;
  esac
}
# The MIRRORBOX_TEST_SKIP component a package belongs to; empty: always needed.
component_of() {
  case $1 in
    xvfb | xauth) echo xvfb ;;
    xdotool) echo xdotool ;;
    chromium-headless-shell) echo chromium ;;
    assimp-testmodels) echo corpus ;;
    nodejs | npm) echo web ;;
    *) echo "" ;;
  esac
}
optional() {
  local c
  c=$(component_of "$1")
  [ -n "$c" ] && skip_allowed "$c"
}

# The Mesa packages missing or older than MESA_MIN, as "package[ version]".
mesa_missing() {
  command -v dpkg-query >/dev/null 2>&1 || return 0
  local p v
  for p in mesa-vulkan-drivers libegl-mesa0 libgl1-mesa-dri; do
    v=$(deb_version "$p")
    if [ -z "$v" ] || ! version_at_least "$v" "$MESA_MIN"; then echo "$p${v:+ $v}"; fi
  done
  [ -n "$(deb_version libvulkan1)" ] || echo libvulkan1
  [ -n "$(deb_version libegl1)" ] || echo libegl1
}
missing_packages() {
  local p
  for p in "${PACKAGES[@]}"; do present "$p" || echo "$p"; done
}

if [ "$(id -u)" -eq 0 ]; then
  APT_SUDO=()
  can_install=yes
elif command -v sudo >/dev/null 2>&1 && sudo -n true 2>/dev/null; then
  APT_SUDO=(sudo)
  can_install=yes
else
  can_install=""
fi
command -v apt-get >/dev/null 2>&1 || can_install=""

# apt-get's outcome so far: "" (not run), or why it failed.
apt_blocked=""   # a lock held past the timeout: no further apt-get call is tried
apt_failures=()  # apt-get's errors (exit codes; its messages were shown)
updated=""
update_lists() {
  [ -z "$updated" ] || return 0
  updated=yes
  echo "install-system-deps: apt-get update..."
  local rc=0
  apt_get -qq update >/dev/null || rc=$?
  if [ "$rc" -eq "$APT_LOCK_TIMED_OUT" ]; then
    apt_blocked=$APT_ERROR
  elif [ "$rc" -ne 0 ]; then
    # Often one unreachable third-party source: the lists already here may still do.
    echo "install-system-deps: warning: $APT_ERROR; installing from the package lists already here." >&2
    apt_failures+=("$APT_ERROR")
  fi
}
# apt-get install [-t SUITE] PACKAGES...; false when it failed. When one call for all of them
# fails, each is tried alone, so one package apt cannot install does not keep the others out
# (the check afterwards names what is still missing).
install_with_apt() {
  [ -z "$apt_blocked" ] || return 1
  update_lists
  [ -z "$apt_blocked" ] || return 1
  local opts=() rc=0 p all_ok=yes
  if [ "$1" = -t ]; then
    opts=(-t "$2")
    shift 2
  fi
  apt_get install -y -qq --no-install-recommends "${opts[@]}" "$@" >/dev/null || rc=$?
  [ "$rc" -eq 0 ] && return 0
  if [ "$rc" -eq "$APT_LOCK_TIMED_OUT" ]; then
    apt_blocked=$APT_ERROR
    return 1
  fi
  if [ $# -eq 1 ]; then
    apt_failures+=("$APT_ERROR")
    return 1
  fi
  echo "install-system-deps: apt-get could not install them together; trying each alone..." >&2
  for p in "$@"; do
    rc=0
    apt_get install -y -qq --no-install-recommends "${opts[@]}" "$p" >/dev/null || rc=$?
    if [ "$rc" -eq "$APT_LOCK_TIMED_OUT" ]; then
      apt_blocked=$APT_ERROR
      return 1
    elif [ "$rc" -ne 0 ]; then
      apt_failures+=("$APT_ERROR")
      all_ok=""
    fi
  done
  [ -n "$all_ok" ]
}

# --- Mesa -------------------------------------------------------------------------------
mapfile -t mesa_old < <(mesa_missing)
command -v dpkg-query >/dev/null 2>&1 ||
  echo "install-system-deps: warning: no dpkg-query here, so Mesa's version is not checked: mirrorbox needs Mesa >= $MESA_MIN (lavapipe, EGL/GL); \`mirrorbox info\` names the driver it finds." >&2
mesa_note=""
if [ ${#mesa_old[@]} -gt 0 ]; then
  echo "install-system-deps: Mesa >= $MESA_MIN needed; missing or older: ${mesa_old[*]}."
  if ! is_bookworm; then
    mesa_note="not Debian 12: install Mesa >= $MESA_MIN (lavapipe: mesa-vulkan-drivers; EGL/GL: libegl-mesa0, libgl1-mesa-dri) from your distribution; older lavapipe leaks memory per render pass"
  elif [ -n "$can_install" ]; then
    if ! grep -rqs 'bookworm-backports' /etc/apt/sources.list /etc/apt/sources.list.d/; then
      echo "install-system-deps: adding Debian's bookworm-backports suite (deb822: /etc/apt/sources.list.d/bookworm-backports.sources)."
      printf '%s\n' 'Types: deb' 'URIs: http://deb.debian.org/debian' 'Suites: bookworm-backports' \
        'Components: main' 'Signed-By: /usr/share/keyrings/debian-archive-keyring.gpg' |
        "${APT_SUDO[@]}" tee /etc/apt/sources.list.d/bookworm-backports.sources >/dev/null
    fi
    echo "install-system-deps: installing ${MESA_PACKAGES[*]} from bookworm-backports (Mesa 25: lavapipe without the per-pass leak, ray queries)..."
    install_with_apt -t bookworm-backports "${MESA_PACKAGES[@]}" &&
      echo "install-system-deps: Mesa $(deb_version mesa-vulkan-drivers) installed."
  fi
fi

# --- the viewer's libraries and display, GNU time, Chromium, the OBJ corpus --------------
mapfile -t missing < <(missing_packages)
if [ ${#missing[@]} -gt 0 ] && [ -n "$can_install" ] && [ -z "$apt_blocked" ]; then
  needed=()
  skippable=()
  for p in "${missing[@]}"; do
    if optional "$p"; then skippable+=("$p"); else needed+=("$p"); fi
  done
  if [ ${#needed[@]} -gt 0 ]; then
    echo "install-system-deps: installing ${needed[*]} with apt-get (the viewer's window libraries and virtual display, GNU time, Chromium, the OBJ corpus: whichever are missing)..."
    install_with_apt "${needed[@]}" && echo "install-system-deps: installed ${needed[*]}."
  fi
  # A component the user agreed to skip is tried on its own, so its failure fails nothing else.
  if [ ${#skippable[@]} -gt 0 ]; then
    echo "install-system-deps: installing ${skippable[*]} with apt-get (MIRRORBOX_TEST_SKIP: $(skip_listed); a failure here is only a warning)..."
    install_with_apt "${skippable[@]}" && echo "install-system-deps: installed ${skippable[*]}."
  fi
fi

# --- what is still missing --------------------------------------------------------------
mapfile -t mesa_old < <(mesa_missing)
mapfile -t missing < <(missing_packages)
errors=()
warnings=()
components=()
[ ${#mesa_old[@]} -eq 0 ] || errors+=("Mesa >= $MESA_MIN (${mesa_old[*]})")
for p in "${missing[@]}"; do
  c=$(component_of "$p")
  if optional "$p"; then
    warnings+=("$p (component $c)")
  else
    errors+=("$p")
    [ -z "$c" ] || [[ " ${components[*]} " == *" $c "* ]] || components+=("$c")
  fi
done

# Why they are not installed, in one sentence: $1 says whether only Mesa is missing.
why() {
  local only_mesa=$1
  if [ -n "$mesa_note" ] && [ ${#mesa_old[@]} -gt 0 ]; then
    printf 'Mesa: %s' "$mesa_note"
    [ "$only_mesa" = yes ] && return
    printf '; the others: '
  fi
  if ! command -v apt-get >/dev/null 2>&1; then
    echo "there is no apt-get here: install them with your distribution's package manager"
  elif [ -z "$can_install" ]; then
    echo "this is not root and sudo is not available without a password: run scripts/install-system-deps.sh as root (or with sudo)"
  elif [ -n "$apt_blocked" ]; then
    echo "$apt_blocked"
  elif [ ${#apt_failures[@]} -gt 0 ]; then
    printf '%s; ' "${apt_failures[@]}" | sed 's/; $//'
  else
    echo "apt-get reported success, but they are still not there (the checks: ldconfig -p for the libraries, the commands on PATH, /usr/share/assimp/models/OBJ)"
  fi
}

if [ ${#warnings[@]} -gt 0 ]; then
  echo "install-system-deps: warning: not installed: ${warnings[*]}; MIRRORBOX_TEST_SKIP=$(skip_listed) agrees to skip them, so their tests will skip. Why: $(why no)." >&2
fi
if [ ${#errors[@]} -gt 0 ]; then
  only_mesa=no
  [ ${#errors[@]} -eq 1 ] && [ ${#mesa_old[@]} -gt 0 ] && only_mesa=yes
  echo "install-system-deps: error: not installed, and needed: ${errors[*]}. Why: $(why "$only_mesa").${components[*]:+ To go without them instead, agree to skip their components: MIRRORBOX_TEST_SKIP=$(IFS=,; echo "${components[*]}").}" >&2
  exit 1
fi
if [ -z "$updated" ] && [ ${#warnings[@]} -eq 0 ]; then
  echo "install-system-deps: Mesa $(deb_version mesa-vulkan-drivers 2>/dev/null), X11 libraries, Xvfb, xdotool, GNU time, Chromium and the OBJ corpus present; nothing to install."
else
  echo "install-system-deps: done: everything needed is present (Mesa $(deb_version mesa-vulkan-drivers 2>/dev/null))${warnings[*]:+, except the packages of the skipped components named above}."
fi
exit 0
