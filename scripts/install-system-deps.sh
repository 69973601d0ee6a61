#!/usr/bin/env bash
# Installs what mirrorbox needs from the system, saying what it does.
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
# Uses apt-get when run as root (or through sudo when available). Idempotent: does nothing
# when everything is present and current. Never fails the caller: without a driver, GPU
# tests and `mirrorbox info` will say so.
set -u
MESA_MIN=25.0.7
MESA_PACKAGES=(mesa-vulkan-drivers libvulkan1 libegl1 libegl-mesa0 libgl1-mesa-dri)

have_lib() { ldconfig -p 2>/dev/null | grep -q "$1"; }
# The installed version of a Debian package, empty when it is not installed.
deb_version() { dpkg-query -W -f='${Status} ${Version}\n' "$1" 2>/dev/null | awk '$3 == "installed" { print $4 }'; }
# True when the Debian version $1 is at least $2.
version_at_least() { dpkg --compare-versions "$1" ge "$2"; }

is_bookworm() { [ -r /etc/os-release ] && . /etc/os-release && [ "${VERSION_CODENAME:-}" = bookworm ]; }

if [ "$(id -u)" -eq 0 ]; then
  sudo=()
elif command -v sudo >/dev/null 2>&1 && sudo -n true 2>/dev/null; then
  sudo=(sudo)
else
  sudo=(none)
fi
can_install() { command -v apt-get >/dev/null 2>&1 && [ "${sudo[0]:-}" != none ]; }
export DEBIAN_FRONTEND=noninteractive

# --- Mesa -------------------------------------------------------------------------------
mesa_old=()
if command -v dpkg-query >/dev/null 2>&1; then
  for p in mesa-vulkan-drivers libegl-mesa0 libgl1-mesa-dri; do
    v=$(deb_version "$p")
    if [ -z "$v" ] || ! version_at_least "$v" "$MESA_MIN"; then mesa_old+=("$p${v:+ $v}"); fi
  done
  [ -n "$(deb_version libvulkan1)" ] || mesa_old+=(libvulkan1)
  [ -n "$(deb_version libegl1)" ] || mesa_old+=(libegl1)
fi

if [ ${#mesa_old[@]} -gt 0 ]; then
  echo "install-system-deps: Mesa >= $MESA_MIN needed; missing or older: ${mesa_old[*]}."
  if ! is_bookworm; then
    echo "install-system-deps: not Debian 12: install Mesa >= $MESA_MIN (lavapipe: mesa-vulkan-drivers; EGL/GL: libegl-mesa0, libgl1-mesa-dri) from your distribution; older lavapipe leaks memory per render pass." >&2
  elif ! can_install; then
    echo "install-system-deps: run as root (or with sudo) to install Mesa >= $MESA_MIN from bookworm-backports." >&2
  else
    if ! grep -rqs 'bookworm-backports' /etc/apt/sources.list /etc/apt/sources.list.d/; then
      echo "install-system-deps: adding Debian's bookworm-backports suite (deb822: /etc/apt/sources.list.d/bookworm-backports.sources)."
      printf '%s\n' 'Types: deb' 'URIs: http://deb.debian.org/debian' 'Suites: bookworm-backports' \
        'Components: main' 'Signed-By: /usr/share/keyrings/debian-archive-keyring.gpg' |
        "${sudo[@]}" tee /etc/apt/sources.list.d/bookworm-backports.sources >/dev/null
    fi
    echo "install-system-deps: installing ${MESA_PACKAGES[*]} from bookworm-backports (Mesa 25: lavapipe without the per-pass leak, ray queries)..."
    if "${sudo[@]}" apt-get update -qq &&
      "${sudo[@]}" apt-get install -y -qq --no-install-recommends -t bookworm-backports "${MESA_PACKAGES[@]}" >/dev/null; then
      echo "install-system-deps: Mesa $(deb_version mesa-vulkan-drivers) installed."
    else
      echo "install-system-deps: apt-get failed; wgpu may find no adapter or an old lavapipe (mirrorbox info will say)." >&2
    fi
  fi
fi

# --- the viewer's libraries and display -------------------------------------------------
missing=()
have_lib 'libX11\.so\.6' || missing+=(libx11-6)
have_lib 'libX11-xcb\.so\.1' || missing+=(libx11-xcb1)
have_lib 'libXcursor\.so\.1' || missing+=(libxcursor1)
have_lib 'libXrandr\.so\.2' || missing+=(libxrandr2)
have_lib 'libXi\.so\.6' || missing+=(libxi6)
have_lib 'libxkbcommon-x11\.so\.0' || missing+=(libxkbcommon-x11-0)
command -v Xvfb >/dev/null 2>&1 || missing+=(xvfb)
command -v xauth >/dev/null 2>&1 || missing+=(xauth)
command -v xdotool >/dev/null 2>&1 || missing+=(xdotool)
command -v /usr/bin/time >/dev/null 2>&1 || missing+=(time)
# The reports test opens every HTML report in headless Chromium (issue 38).
command -v chromium-headless-shell >/dev/null 2>&1 || missing+=(chromium-headless-shell)
# Public test assets nobody here wrote (issue 40): the OBJ corpus test loads every OBJ file.
[ -d /usr/share/assimp/models/OBJ ] || missing+=(assimp-testmodels)

if [ ${#missing[@]} -eq 0 ]; then
  [ ${#mesa_old[@]} -gt 0 ] || echo "install-system-deps: Mesa $(deb_version mesa-vulkan-drivers), X11 libraries and Xvfb present; nothing to install."
  exit 0
fi
if ! can_install; then
  echo "install-system-deps: missing ${missing[*]}; run as root with apt-get to install them." >&2
  exit 0
fi
echo "install-system-deps: installing ${missing[*]} with apt-get (the viewer's window libraries, a virtual display, GNU time)..."
if "${sudo[@]}" apt-get update -qq && "${sudo[@]}" apt-get install -y -qq --no-install-recommends "${missing[@]}" >/dev/null; then
  echo "install-system-deps: done."
else
  echo "install-system-deps: apt-get failed; the viewer's tests will say what is missing." >&2
fi
exit 0
