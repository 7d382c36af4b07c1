#!/usr/bin/env bash
# Checks that sinew's animated GIFs open and play in a browser (headless Chromium).
#
#   tools/browser-check/run.sh [GIF ...]
#
# With no GIF given, writes the synthetic test animation (examples/sequence_demo.rs) as
# demo.gif (transparent) and demo_on_white.gif (composited over white) and checks both.
# Installs chromium and nodejs from Debian's packages when missing (needs root or sudo).
# Output: $OUT_DIR (default ${TMPDIR:-/tmp}/sinew-browser-check)/<gif name>/shot_<ms>ms.png and
# report.json per GIF. Screenshot times: $TIMES_MS (default 100,400,700 ms after page load).
# Exit status: 0 when every GIF animates, 1 when one does not, 2 on a setup error.
set -euo pipefail

here="$(cd "$(dirname "${BASH_SOURCE[0]}")" && pwd)"
repo="$(cd "$here/../.." && pwd)"
out="${OUT_DIR:-${TMPDIR:-/tmp}/sinew-browser-check}"
times="${TIMES_MS:-100,400,700}"

as_root() {
  if [ "$(id -u)" -eq 0 ]; then "$@"
  elif command -v sudo >/dev/null; then sudo "$@"
  else echo "need root (or sudo) to install $*" >&2; exit 2
  fi
}

apt_updated=no
install_package() {
  if [ "$apt_updated" = no ]; then
    as_root apt-get update -qq
    apt_updated=yes
  fi
  apt-cache policy "$1"
  as_root env DEBIAN_FRONTEND=noninteractive apt-get install -y -qq --no-install-recommends "$1"
}

command -v chromium >/dev/null || install_package chromium
command -v node >/dev/null || install_package nodejs
# The DevTools pipe and ImageDecoder need a recent Node and Chromium; say which ones ran.
echo "chromium: $(chromium --version 2>/dev/null | head -n1)"
echo "node: $(node --version)"

gifs=("$@")
if [ "${#gifs[@]}" -eq 0 ]; then
  (cd "$repo" && cargo run --release --quiet --no-default-features --example sequence_demo -- \
    "$out/demo" 256 24 24)
  gifs=("$out/demo/demo.gif" "$out/demo/demo_on_white.gif")
fi

mkdir -p "$out"
status=0
for gif in "${gifs[@]}"; do
  name="$(basename "$gif" .gif)"
  echo "== $gif"
  # Chromium's chatter (D-Bus, GPU) goes to stderr; the report is on stdout.
  node "$here/check.mjs" "$gif" "$out/$name" "$times" 2>"$out/$name.stderr.log" || status=$?
  echo "screenshots: $out/$name/shot_*ms.png"
done
exit "$status"
