#!/usr/bin/env bash
# Runs check.mjs (the official DragonBonesJS runtime on a sinew export), pinned.
#
#   tools/dragonbones-check/run.sh NAME_ske.json NAME_tex.json REQUEST.json OUT.json
#
# Installs what it needs on first use: Node.js and npm from Debian's packages when missing
# (needs root or sudo), then `npm ci` from package-lock.json into tools/dragonbones-check/node_modules.
# Exit status: check.mjs's (0 loaded, 2 refused), or 3 on a setup error.
set -euo pipefail
here="$(cd "$(dirname "${BASH_SOURCE[0]}")" && pwd)"

as_root() {
  if [ "$(id -u)" -eq 0 ]; then "$@"
  elif command -v sudo >/dev/null; then sudo "$@"
  else echo "dragonbones-check: need root (or sudo) to install $*" >&2; exit 3
  fi
}
if ! command -v node >/dev/null || ! command -v npm >/dev/null; then
  as_root apt-get update -qq >&2
  as_root env DEBIAN_FRONTEND=noninteractive apt-get install -y -qq --no-install-recommends nodejs npm >&2
fi

# Reinstall when the lock file changed since the last install, or the package is gone. Tests
# run this script in parallel: the check and the install hold an exclusive lock, so one
# process installs while the others wait (npm ci deletes node_modules first, which a
# concurrent `node` would read half-written), and the others then find the stamp.
stamp="$here/node_modules/.sinew-lock"
installed="$here/node_modules/@cocos/dragonbones-js/package.json"
exec 9>"$here/.install.lock"
flock 9
if ! cmp -s "$here/package-lock.json" "$stamp" 2>/dev/null || [ ! -f "$installed" ]; then
  (cd "$here" && npm ci --no-audit --no-fund --loglevel=error >&2) || { echo "dragonbones-check: npm ci failed" >&2; exit 3; }
  cp "$here/package-lock.json" "$stamp"
fi
exec 9>&-
exec node "$here/check.mjs" "$@"
