#!/usr/bin/env bash
# `sinew batch --ray` on a two-node Ray cluster on this machine, against a local `sinew batch`:
#
#   tools/ray/run.sh
#
# Installs tools/ray/.venv with the pinned ray (install.sh; cached: reruns skip it). Writes a
# batch of 23 jobs (the bundled character rigged, its four animations rendered, two Spine
# exports, four generated sprites rigged, twelve generated line drawings colorized), runs it
# locally, then on a Ray head and a second worker node, both started with
# `--node-ip-address 127.0.0.1` (SINEW_RAY_LOOPBACK=1 keeps Ray from replacing the address by
# the machine's: see sinew_ray_loopback.py; every Ray socket is checked to be on 127.0.0.1).
# Mid-run it kills the worker process running the character's rig (SIGKILL); Ray reruns the
# task. Checks: every job done, the killed job ran again in another process, every output
# byte-identical to the local run's, and a rerun skips every job.
#
# Where ray cannot be installed (no python3 venv, no network to PyPI) it says "skipped" and why
# and exits 0. Exit status: 0 passed or skipped, 1 failed.
set -euo pipefail
here="$(cd "$(dirname "${BASH_SOURCE[0]}")" && pwd)"
root="$(cd "$here/../.." && pwd)"
source "$here/lib.sh"

cd "$root"
if ! reason="$("$here/install.sh" 2>&1 >/dev/null)"; then
  skip "${reason:-cannot install ray}"
fi
# The binary `cargo test` built (as tools/editor-x11/run.sh does).
cargo test --release --locked --quiet --no-run --test batch
sinew="${CARGO_TARGET_DIR:-$root/target}/release/sinew"

make_work

# The batch, twice at the same depth (the demo rig names its images in its own character.parts/).
python3 "$here/make_batch.py" "$work/local" "$root/assets/character" >/dev/null
"$sinew" demo -o "$work/local/in/demo" >/dev/null
mkdir "$work/ray"
cp -a "$work/local/in" "$work/local/manifest.json" "$work/ray/"
jobs="$(python3 -c 'import json,sys; print(len(json.load(open(sys.argv[1]))["jobs"]))' "$work/local/manifest.json")"

started=$SECONDS
"$sinew" batch "$work/local/manifest.json" --jobs 2 >"$work/local-report.json" ||
  fail "the local batch failed: $(tail -c 600 "$work/local-report.json")"
local_s=$((SECONDS - started))

started=$SECONDS
start_cluster
cluster_s=$((SECONDS - started))

# The batch on Ray; the character's rig is killed under it.
export SINEW_RAY_LOG_DIR="$work/attempts"
mkdir "$SINEW_RAY_LOG_DIR"
attempts="$SINEW_RAY_LOG_DIR/attempts.log"
started=$SECONDS
"$sinew" batch "$work/ray/manifest.json" --ray "$address" >"$work/ray-report.json" 2>"$work/ray.err" &
batch_pid=$!
killed=""
for _ in $(seq 600); do
  pid="$(awk -F'\t' '$1 == "character" { print $2; exit }' "$attempts" 2>/dev/null || true)"
  if [ -n "$pid" ]; then
    # Into the task, well before its end: on the release profile the rig takes about 0.5 s.
    sleep 0.1
    # Still running the task (Ray titles a worker with the task it runs).
    if tr '\0' ' ' <"/proc/$pid/cmdline" 2>/dev/null | grep -q '^ray::run_job'; then
      kill -KILL "$pid" && killed="$pid"
    fi
    check_loopback
    break
  fi
  kill -0 "$batch_pid" 2>/dev/null || break
  sleep 0.1
done
[ -n "$killed" ] || fail "found no worker running the character's rig to kill"
rc=0
wait "$batch_pid" || rc=$?
ray_s=$((SECONDS - started))
[ "$rc" -eq 0 ] || fail "the Ray batch exited with $rc: $(tail -c 800 "$work/ray.err") $(grep -m3 '"error"' "$work/ray-report.json" || true)"

python3 - "$work/ray-report.json" "$attempts" "$killed" "$jobs" <<'PY' || exit 1
import json, sys
report, attempts, killed, jobs = json.load(open(sys.argv[1])), sys.argv[2], sys.argv[3], int(sys.argv[4])
bad = [j for j in report["jobs"] if j["status"] != "done"]
if len(report["jobs"]) != jobs or bad:
    sys.exit(f"ray-batch: FAILED: not every job done on Ray: {bad[:3]}")
runs = [line.split("\t") for line in open(attempts).read().splitlines()]
character = [pid for name, pid in runs if name == "character"]
if len(character) < 2 or character[0] != killed or character[-1] == killed:
    sys.exit(f"ray-batch: FAILED: the killed task was not rerun elsewhere: {character}")
PY
diff -r "$work/local/out" "$work/ray/out" >"$work/diff.txt" 2>&1 ||
  fail "Ray's outputs differ from the local run's: $(head -5 "$work/diff.txt")"
files="$(find "$work/ray/out" -type f | wc -l)"

# A rerun does nothing.
"$sinew" batch "$work/ray/manifest.json" --ray "$address" >"$work/rerun.json" 2>/dev/null ||
  fail "the rerun failed"
python3 -c 'import json,sys; r=json.load(open(sys.argv[1])); sys.exit(0 if r["skipped"] == len(r["jobs"]) else "ray-batch: FAILED: the rerun ran jobs again")' "$work/rerun.json"

say "passed: $jobs jobs on 2 Ray nodes (one worker killed mid-task and rerun), $files output files byte-identical to the local run; local ${local_s} s, cluster start ${cluster_s} s, Ray run ${ray_s} s"
