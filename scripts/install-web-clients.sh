#!/usr/bin/env bash
# Installs the exchange's web clients (clients/web: three.js and puppeteer-core, docs/exchange.md)
# with `npm ci` from clients/web/package-lock.json, exactly the pinned versions.
#   - Skips when clients/web/node_modules was installed from the same lockfile: the lockfile's
#     SHA-256 is stored in node_modules/.lock-hash after a successful install.
#   - Retries `npm ci` (the network) up to MIRRORBOX_NPM_TRIES times (default 3), waiting 5, 10,
#     ... seconds between tries.
#   - Needs node >= 18 and npm on PATH; it does not install Chromium (run.mjs drives the system's
#     chromium-headless-shell: scripts/install-system-deps.sh installs it).
# Exit 0: installed (or already current), or not but MIRRORBOX_TEST_SKIP names `web`
# (scripts/lib/skip.sh: a warning, and the web client's test skips); 1: node/npm missing or
# npm ci failed every try; 2: a bad MIRRORBOX_NPM_TRIES or MIRRORBOX_TEST_SKIP.
set -euo pipefail

here="$(cd "$(dirname "$0")" && pwd)"
client="$(cd "$here/../clients/web" && pwd)"
lock="$client/package-lock.json"
stamp="$client/node_modules/.lock-hash"
tries="${MIRRORBOX_NPM_TRIES:-3}"

# shellcheck source=scripts/lib/skip.sh
. "$here/lib/skip.sh"
skip_check_list install-web-clients

say() { printf 'install-web-clients: %s\n' "$*"; }
die() {
  if skip_allowed web; then
    say "warning: $* (MIRRORBOX_TEST_SKIP=$(skip_listed) agrees to go without the web clients)" >&2
    exit 0
  fi
  say "$*" >&2
  exit 1
}

if ! [[ "$tries" =~ ^[1-9][0-9]*$ ]]; then
  say "MIRRORBOX_NPM_TRIES must be a positive integer, not '$tries'" >&2
  exit 2
fi
command -v node >/dev/null 2>&1 || die "node is not on PATH (node >= 18 is needed)"
command -v npm >/dev/null 2>&1 || die "npm is not on PATH"
node_major="$(node -p 'process.versions.node.split(".")[0]')"
(( node_major >= 18 )) || die "node $(node --version) is too old: node >= 18 is needed"
[[ -f "$lock" ]] || die "no $lock: the clients' lockfile is missing"

hash="$(sha256sum "$lock" | cut -d' ' -f1)"
if [[ -f "$stamp" && "$(cat "$stamp")" == "$hash" ]]; then
  say "clients/web is current (node_modules installed from this package-lock.json); nothing to do"
  exit 0
fi

say "npm ci in clients/web (node $(node --version), npm $(npm --version))"
for (( try = 1; try <= tries; try++ )); do
  # --ignore-scripts: no dependency needs an install script (puppeteer-core downloads nothing).
  if (cd "$client" && npm ci --ignore-scripts --no-audit --no-fund); then
    printf '%s\n' "$hash" > "$stamp"
    version() { (cd "$client" && node -p "require('./node_modules/$1/package.json').version" 2>/dev/null) || echo '?'; }
    say "installed clients/web from package-lock.json: three.js $(version three), Babylon.js $(version @babylonjs/core)"
    exit 0
  fi
  if (( try < tries )); then
    wait_s=$(( 5 * try ))
    say "npm ci failed (try $try of $tries); retrying in ${wait_s} s" >&2
    sleep "$wait_s"
  fi
done
die "npm ci failed $tries times in $client: is the npm registry reachable (npm config get registry: $(npm config get registry 2>/dev/null || echo '?'))?"
