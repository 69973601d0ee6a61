#!/usr/bin/env bash
# Installs what mirrorbox needs from the system and is missing, saying what it does.
#   - Mesa's software Vulkan driver (lavapipe) and the Vulkan loader, so wgpu can render
#     on a machine without a GPU (Debian/Ubuntu: mesa-vulkan-drivers, libvulkan1);
#   - Mesa's EGL/GL drivers as the fallback backend, which the GL backend tests render with
#     (libegl1: the libEGL.so.1 wgpu loads; libegl-mesa0: Mesa's EGL vendor library;
#     libgl1-mesa-dri: llvmpipe, swrast_dri.so);
#   - for `mirrorbox view`: the X11 client libraries winit loads at run time (libx11-6,
#     libx11-xcb1, libxcursor1, libxrandr2, libxi6, libxkbcommon-x11-0), Xvfb (xvfb,
#     xauth for xvfb-run), the virtual display its tests and screenshots run on, and xdotool,
#     with which the tests type and drag in it.
# Uses apt-get when run as root (or through sudo when available). Idempotent: does nothing
# when everything is present. Never fails the caller: without a driver, GPU tests will say so.
set -u

have_vulkan_driver() {
  # Either folder may hold the drivers' ICD files (ls fails if any of its globs is empty).
  { ls /usr/share/vulkan/icd.d/*.json >/dev/null 2>&1 || ls /etc/vulkan/icd.d/*.json >/dev/null 2>&1; } &&
    ldconfig -p 2>/dev/null | grep -q 'libvulkan\.so\.1'
}
have_egl() {
  ldconfig -p 2>/dev/null | grep -q 'libEGL\.so\.1' &&
    ldconfig -p 2>/dev/null | grep -q 'libEGL_mesa\.so\.0' &&
    ls /usr/lib/*/dri/swrast_dri.so /usr/lib*/dri/swrast_dri.so 2>/dev/null | grep -q .
}

have_lib() { ldconfig -p 2>/dev/null | grep -q "$1"; }

missing=()
have_vulkan_driver || missing+=(mesa-vulkan-drivers libvulkan1)
have_egl || missing+=(libegl1 libegl-mesa0 libgl1-mesa-dri)
have_lib 'libX11\.so\.6' || missing+=(libx11-6)
have_lib 'libX11-xcb\.so\.1' || missing+=(libx11-xcb1)
have_lib 'libXcursor\.so\.1' || missing+=(libxcursor1)
have_lib 'libXrandr\.so\.2' || missing+=(libxrandr2)
have_lib 'libXi\.so\.6' || missing+=(libxi6)
have_lib 'libxkbcommon-x11\.so\.0' || missing+=(libxkbcommon-x11-0)
command -v Xvfb >/dev/null 2>&1 || missing+=(xvfb)
command -v xauth >/dev/null 2>&1 || missing+=(xauth)
command -v xdotool >/dev/null 2>&1 || missing+=(xdotool)

if [ ${#missing[@]} -eq 0 ]; then
  echo "install-system-deps: Vulkan driver, EGL, X11 libraries and Xvfb present; nothing to install."
  exit 0
fi

if ! command -v apt-get >/dev/null 2>&1; then
  echo "install-system-deps: missing ${missing[*]} and no apt-get here; install Mesa's Vulkan (lavapipe) or EGL drivers by hand." >&2
  exit 0
fi
if [ "$(id -u)" -eq 0 ]; then
  sudo=()
elif command -v sudo >/dev/null 2>&1; then
  sudo=(sudo)
else
  echo "install-system-deps: missing ${missing[*]}; run as root to install them." >&2
  exit 0
fi

echo "install-system-deps: installing ${missing[*]} with apt-get (software rendering for wgpu, a virtual display for the viewer)..."
export DEBIAN_FRONTEND=noninteractive
if "${sudo[@]}" apt-get update -qq && "${sudo[@]}" apt-get install -y -qq --no-install-recommends "${missing[@]}" >/dev/null; then
  echo "install-system-deps: done."
else
  echo "install-system-deps: apt-get failed; wgpu may find no adapter (mirrorbox info will say)." >&2
fi
exit 0
