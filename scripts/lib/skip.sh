# shellcheck shell=bash
# MIRRORBOX_TEST_SKIP: the components a user agrees to go without (comma-separated; CI sets
# none). Sourced by the install scripts and scripts/test.sh; the tests read the same list.
#   corpus      assimp-testmodels (/usr/share/assimp/models): the OBJ corpus test
#   xvfb        Xvfb and xauth: the viewer's tests on a virtual display
#   xdotool     xdotool: the viewer's tests that type and drag
#   slurm       slurm-wlm and munge, or root: the local Slurm test
#   mitsuba     tools/mitsuba/.venv and libllvm19: the Mitsuba 3 agreement tests
#   chromium    chromium-headless-shell: the reports opened in a browser
#   raytracing  the adapter's ray queries (Mesa >= 25's lavapipe has them)
#   web         nodejs, npm and clients/web's npm packages: the web engines' exchange test
# A component not in the list is required: an install script that cannot install it exits
# non-zero naming the packages, and a test that finds it missing fails. A listed one is not:
# the install scripts warn instead of failing, and a test that skips for it appends
# `<component>\t<test name>\t<reason>` to the file named by MIRRORBOX_SKIP_LOG.
#
# skip_check_list PREFIX   exits 2 (message prefixed PREFIX) when the list names something
#                          that is no component
# skip_allowed COMPONENT   true when the list names COMPONENT
# skip_listed              the list, normalised: names separated by ", ", or "none"

MIRRORBOX_COMPONENTS=(corpus xvfb xdotool slurm mitsuba chromium raytracing web)

# The list's names, one a line, blanks removed and empty entries dropped.
skip_names() {
  local name names
  IFS=, read -r -a names <<<"${MIRRORBOX_TEST_SKIP:-}"
  for name in "${names[@]}"; do
    name=${name//[[:space:]]/}
    [ -z "$name" ] || echo "$name"
  done
}

skip_check_list() {
  local prefix=$1 name known
  while read -r name; do
    for known in "${MIRRORBOX_COMPONENTS[@]}"; do
      [ "$name" = "$known" ] && continue 2
    done
    echo "$prefix: MIRRORBOX_TEST_SKIP='${MIRRORBOX_TEST_SKIP:-}' names '$name', which is no component; the components: ${MIRRORBOX_COMPONENTS[*]} (comma-separated)." >&2
    exit 2
  done < <(skip_names)
}

skip_allowed() {
  local name
  while read -r name; do
    [ "$name" = "$1" ] && return 0
  done < <(skip_names)
  return 1
}

skip_listed() {
  local names
  names=$(skip_names | paste -sd, | sed 's/,/, /g')
  echo "${names:-none}"
}
