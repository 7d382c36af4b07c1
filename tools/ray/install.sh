#!/usr/bin/env bash
# Installs the Ray batch driver's virtual environment, tools/ray/.venv, with the pinned ray of
# requirements.txt, unless it is already there with that version (reruns take no time).
#
#   tools/ray/install.sh        # prints the venv's python on success
#
# Exit status: 0 installed (or already there), 3 cannot install (no python3 with venv, no
# network to PyPI, no wheel for this platform): the reason is on stderr in one line.
set -euo pipefail
here="$(cd "$(dirname "${BASH_SOURCE[0]}")" && pwd)"
venv="$here/.venv"
want="$(sed -n 's/^ray==//p' "$here/requirements.txt")"
python="$venv/bin/python"
# Every Python of the venv imports sinew_ray_loopback.py at start-up when SINEW_RAY_LOOPBACK=1
# (the test's cluster stays on 127.0.0.1; see that file).
add_loopback_hook() {
  local site
  site="$("$python" -c 'import sysconfig; print(sysconfig.get_paths()["purelib"])')"
  printf '%s\n%s\n' "$here" \
    'import os; os.environ.get("SINEW_RAY_LOOPBACK") == "1" and __import__("sinew_ray_loopback")' \
    >"$site/sinew_ray_loopback.pth"
}
if [ -x "$python" ] && [ "$("$python" -c 'import ray; print(ray.__version__)' 2>/dev/null)" = "$want" ]; then
  add_loopback_hook
  echo "$python"
  exit 0
fi
command -v python3 >/dev/null || { echo "no python3 on PATH" >&2; exit 3; }
rm -rf "$venv"
log="$(mktemp)"
if ! python3 -m venv "$venv" >"$log" 2>&1; then
  echo "python3 cannot make a venv: $(tail -1 "$log")" >&2; rm -f "$log"; rm -rf "$venv"; exit 3
fi
if ! "$python" -m pip install --quiet --disable-pip-version-check -r "$here/requirements.txt" >"$log" 2>&1; then
  echo "pip cannot install ray==$want: $(grep -v '^\s*$' "$log" | tail -1)" >&2; rm -f "$log"; rm -rf "$venv"; exit 3
fi
rm -f "$log"
add_loopback_hook
echo "$python"
