#!/usr/bin/env bash
# The figures of docs/batch.md: N colorize jobs (generated line art, SIZE² px) run by
# `sinew batch` on 1 and on 2 local workers (--jobs), then on the two-node Ray cluster of
# run.sh (one CPU per node), REPS runs each, interleaved; medians of the batch's wall time, the
# load average before each run, and Ray's overhead per task against the local run on 2 workers.
#
#   tools/ray/figures.sh [N=200] [SIZE=64] [REPS=5]
#
# Uses the binary `cargo test` builds (the dev profile: sinew at opt-level 1, its dependencies
# at 3). Not part of CI.
set -euo pipefail
here="$(cd "$(dirname "${BASH_SOURCE[0]}")" && pwd)"
root="$(cd "$here/../.." && pwd)"
source "$here/lib.sh"
count="${1:-200}" size="${2:-64}" reps="${3:-5}"
cd "$root"
"$here/install.sh" >/dev/null || skip "cannot install ray"
cargo test --locked --quiet --no-run --test batch
sinew="${CARGO_TARGET_DIR:-$root/target}/debug/sinew"
make_work
python3 "$here/make_batch.py" "$work/c" "$root/assets/character" --only-colorize \
  --colorize "$count" --size "$size" >/dev/null
manifest="$work/c/manifest.json"

# One run from scratch: prints "WALL_S LOAD1 SUM_JOB_S".
run() {
  rm -rf "$work/c/out" "$work/c/manifest.state.json"
  local load
  load="$(cut -d' ' -f1 /proc/loadavg)"
  "$sinew" batch "$manifest" "$@" >"$work/report.json"
  python3 -c 'import json,sys; r=json.load(open(sys.argv[1])); assert r["done"] == len(r["jobs"]); print(r["seconds"], sys.argv[2], sum(j["seconds"] for j in r["jobs"]))' "$work/report.json" "$load"
}

start_cluster
: >"$work/w1"; : >"$work/w2"; : >"$work/ray"
run --ray "$address" >/dev/null # the first tasks start the workers' processes
for _ in $(seq "$reps"); do
  run --jobs 1 >>"$work/w1"
  run --jobs 2 >>"$work/w2"
  cp -r "$work/c/out" "$work/local-out"
  run --ray "$address" >>"$work/ray"
  diff -r "$work/local-out" "$work/c/out" >/dev/null || fail "Ray's outputs differ from the local run's"
  rm -rf "$work/local-out"
done
python3 - "$work" "$count" "$size" "$(nproc)" <<'PY'
import statistics, sys
work, count, size, cores = sys.argv[1], int(sys.argv[2]), sys.argv[3], sys.argv[4]
def read(name):
    rows = [list(map(float, line.split())) for line in open(f"{work}/{name}")]
    return [statistics.median(c) for c in zip(*rows)], [r[0] for r in rows]
(w1, l1, j1), a1 = read("w1")
(w2, l2, j2), a2 = read("w2")
(wr, lr, jr), ar = read("ray")
print(f"{count} colorize jobs of {size}x{size} px, {len(a1)} runs each, {cores} cores, medians:")
print(f"  local, 1 worker : {w1:6.2f} s wall (runs {min(a1):.2f}-{max(a1):.2f}), load before {l1:.2f}, job time {1e3 * j1 / count:.1f} ms/job")
print(f"  local, 2 workers: {w2:6.2f} s wall (runs {min(a2):.2f}-{max(a2):.2f}), load before {l2:.2f}, job time {1e3 * j2 / count:.1f} ms/job; speedup {w1 / w2:.2f}x")
print(f"  Ray, 2 nodes x 1 CPU: {wr:6.2f} s wall (runs {min(ar):.2f}-{max(ar):.2f}), load before {lr:.2f}, job time {1e3 * jr / count:.1f} ms/job")
print(f"  Ray overhead per task vs local on 2 workers: {1e3 * (wr - w2) * 2 / count:.1f} ms of a slot ({1e3 * (wr - w2) / count:.1f} ms of wall per task)")
PY
