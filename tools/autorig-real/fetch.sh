#!/usr/bin/env bash
# Rebuilds the real-art set from Debian's packages: downloads the five packages with
# `apt-get download` (needs `apt-get update` once, and rsvg-convert: `apt-get install
# librsvg2-bin`), unpacks them with `dpkg-deb -x`, cuts the characters (make_set.py) and the
# layered files (make_layers.py) into tests/fixtures/autorig-real/. The reference JSONs there
# (joints, layer polygons) are hand-made and kept; the PNGs come out the same from the same
# package versions (listed in sources.json and LICENSES.md).
#
# Usage: tools/autorig-real/fetch.sh [WORK_DIR]   (default: a new temp dir for the packages)
set -euo pipefail
here="$(cd "$(dirname "${BASH_SOURCE[0]}")" && pwd)"
root="$(cd "$here/../.." && pwd)"
set_dir="$root/tests/fixtures/autorig-real"
venv="${VENV:-$here/.venv}"
work="${1:-$(mktemp -d "${TMPDIR:-/tmp}/autorig-real-pkgs.XXXXXX")}"
packages=(
  "tuxpaint-stamps-default=2022.06.04-1"
  "openclipart-svg=1:0.18+dfsg-19"
  "flare-game=1.14-1"
  "pingus-data=0.7.6-5.1"
  "teeworlds-data=0.7.5-2"
)
command -v rsvg-convert >/dev/null || { echo "rsvg-convert missing: apt-get install librsvg2-bin" >&2; exit 2; }
mkdir -p "$work/x"
cd "$work"
for p in "${packages[@]}"; do
  name="${p%%=*}"
  if [[ ! -d "x/$name" ]]; then
    apt-get download "$p"
    dpkg-deb -x "${name}"_*.deb "x/$name"
  fi
done
if [[ ! -x "$venv/bin/python" ]]; then
  python3 -m venv "$venv"
fi
"$venv/bin/python" -m pip install --quiet --disable-pip-version-check -r "$here/requirements.txt"
"$venv/bin/python" "$here/make_set.py" "$work/x" "$set_dir"
"$venv/bin/python" "$here/make_layers.py" "$set_dir"
echo "packages in $work; set in $set_dir" >&2
