#!/usr/bin/env bash
# Benchmark of `sinew auto` on a layered 2048 x 2048 character (issue 42): psd-tools writes the
# bundled character's layers scaled x4 as a PSD (make_big_character.py), then the release
# `sinew auto big.psd -o OUT` runs RUNS times under /usr/bin/time. It prints the wall-time
# median, min and max (s), peak RSS, the load average before and after, and the median share
# of each stage (from OUT/summary.json: read, autorig, rig, motions, render, spine, write).
# The last run's output stays in $work/out (GIFs to look at).
#
# Usage: tools/auto-bench/run.sh [RUNS]
#   env  VENV=DIR   the psd-tools virtual environment (default: /tmp/sinew-layered-venv, the
#                   layered fixtures' and benchmark's)
#        SINEW=BIN  run this binary instead of building target/release/sinew (a copy stays
#                   put while others rebuild the shared target folder)
set -euo pipefail
here="$(cd "$(dirname "${BASH_SOURCE[0]}")" && pwd)"
root="$(cd "$here/../.." && pwd)"
runs="${1:-5}"
venv="${VENV:-/tmp/sinew-layered-venv}"
work="${TMPDIR:-/tmp}/sinew-auto-bench"
mkdir -p "$work"

psd="$work/big.psd"
if [[ ! -f "$psd" ]]; then
  if [[ ! -x "$venv/bin/python" ]]; then
    python3 -m venv "$venv"
  fi
  "$venv/bin/python" -m pip install --quiet --disable-pip-version-check \
    -r "$root/tools/layered-fixtures/requirements.txt" numpy
  "$venv/bin/python" "$here/make_big_character.py" "$psd" 4
fi
echo "input: $(du -h "$psd" | cut -f1) $psd"

if [[ -n "${SINEW:-}" ]]; then
  sinew="$SINEW"
else
  (cd "$root" && cargo build --release --quiet --bin sinew)
  sinew="$root/target/release/sinew"
fi

echo "load average before: $(cut -d' ' -f1-3 /proc/loadavg)"
times=() rss=() summaries=()
for k in $(seq "$runs"); do
  # Each run replaces the previous run's folder (as a person rerunning it would).
  /usr/bin/time -f "%e %M" -o "$work/time.txt" "$sinew" auto "$psd" -o "$work/out" >"$work/stdout.txt"
  read -r t m <"$work/time.txt"
  times+=("$t"); rss+=("$m")
  cp "$work/out/summary.json" "$work/summary.$k.json"
  summaries+=("$work/summary.$k.json")
done
echo "load average after: $(cut -d' ' -f1-3 /proc/loadavg)"
python3 - "${times[*]}" "${rss[*]}" "${summaries[@]}" <<'PY'
import json, statistics, sys
times = [float(t) for t in sys.argv[1].split()]
rss = [int(m) for m in sys.argv[2].split()]
runs = [json.load(open(p)) for p in sys.argv[3:]]
print(f"sinew auto: wall median {statistics.median(times):.2f} s [min {min(times):.2f}, max {max(times):.2f}] "
      f"over {len(times)} runs ({' '.join(f'{t:.2f}' for t in times)}); peak RSS median "
      f"{statistics.median(rss) / 1024:.0f} MB")
s = runs[-1]
print(f"  {s['canvas_px'][0]}x{s['canvas_px'][1]} px, {len(s['parts'])} parts, {len(s['bones'])} bones, "
      f"template {s['template']}, {len(s['motions'])} motions, "
      f"{sum(r['frames'] for r in s['renders'])} frames rendered, {len(s['files'])} files")
print("  stage      median s   share")
for k, stage in enumerate(s["stages"]):
    secs = statistics.median(r["stages"][k]["seconds"] for r in runs)
    share = statistics.median(r["stages"][k]["share"] for r in runs)
    print(f"  {stage['stage']:<9} {secs:>8.2f}   {share * 100:>4.0f} %")
PY
