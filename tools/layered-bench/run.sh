#!/usr/bin/env bash
# Benchmark of layered-art import at production size (issue 21): psd-tools writes a 4096 x 4096
# PSD of 40 pixel layers (make_big_psd.py), then the release `sinew` runs two commands on it,
# each RUNS times under /usr/bin/time:
#   autorig: `sinew autorig big.psd` (read, union silhouette, skeleton, handles written);
#   rig:     `sinew rig big.psd -o rig.json` (read, write the trimmed parts, trace and mesh
#            every layer, write the document).
# It prints wall-time median, min and max (s), peak RSS (MB) and the load average.
#
# Usage: tools/layered-bench/run.sh [RUNS]
#   env  VENV=DIR   the psd-tools virtual environment (default: /tmp/sinew-layered-venv, the
#                   fixtures script's)
set -euo pipefail
here="$(cd "$(dirname "${BASH_SOURCE[0]}")" && pwd)"
root="$(cd "$here/../.." && pwd)"
runs="${1:-5}"
venv="${VENV:-/tmp/sinew-layered-venv}"
work="${TMPDIR:-/tmp}/sinew-layered-bench"
mkdir -p "$work"

if [[ ! -x "$venv/bin/python" ]]; then
  python3 -m venv "$venv"
fi
"$venv/bin/python" -m pip install --quiet --disable-pip-version-check \
  -r "$root/tools/layered-fixtures/requirements.txt"
psd="$work/big.psd"
if [[ ! -f "$psd" ]]; then
  "$venv/bin/python" "$here/make_big_psd.py" "$psd" 4096 40
fi
echo "input: $(du -h "$psd" | cut -f1) $psd"

(cd "$root" && cargo build --release --quiet --bin sinew)
sinew="$root/target/release/sinew"

measure() { # NAME ARGS...
  local name=$1; shift
  local times=() rss=()
  for _ in $(seq "$runs"); do
    rm -rf "$work/out"; mkdir -p "$work/out"
    /usr/bin/time -f "%e %M" -o "$work/time.txt" "$sinew" "$@" >/dev/null
    read -r t m <"$work/time.txt"
    times+=("$t"); rss+=("$m")
  done
  python3 - "$name" "${times[*]}" "${rss[*]}" <<'PY'
import statistics, sys
name, times, rss = sys.argv[1], [float(t) for t in sys.argv[2].split()], [int(m) for m in sys.argv[3].split()]
print(f"{name}: wall median {statistics.median(times):.2f} s [min {min(times):.2f}, max {max(times):.2f}] "
      f"over {len(times)} runs; peak RSS median {statistics.median(rss) / 1024:.0f} MB [max {max(rss) / 1024:.0f}]")
PY
}
echo "load average before: $(cut -d' ' -f1-3 /proc/loadavg)"
measure autorig autorig "$psd" -o "$work/out/handles.json"
measure rig rig "$psd" -o "$work/out/rig.json"
echo "load average after: $(cut -d' ' -f1-3 /proc/loadavg)"
du -sh "$work/out/rig.parts" 2>/dev/null | sed 's/^/parts written: /'
