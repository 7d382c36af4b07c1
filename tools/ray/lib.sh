# Shared by run.sh and figures.sh. Expects $here (tools/ray). Defines say, skip, fail,
# make_work (a scratch folder $work, removed with the cluster at exit), start_cluster (a Ray head
# and a second worker node on 127.0.0.1, one CPU each; sets $address) and check_loopback.

ray="$here/.venv/bin/ray"
# The Python `sinew batch --ray` runs its built-in driver with (its default is python3 on PATH).
export SINEW_RAY_PYTHON="$here/.venv/bin/python"
say() { echo "ray-batch: $*"; }
skip() { say "skipped: $*"; exit 0; }
fail() { echo "ray-batch: FAILED: $*" >&2; exit 1; }

make_work() {
  work="$(mktemp -d)"
  pids=()
  trap cleanup EXIT
}

cleanup() {
  # `ray start --block` stops its node's processes when it is terminated.
  for pid in "${pids[@]}"; do kill "$pid" 2>/dev/null || true; done
  for pid in "${pids[@]}"; do wait "$pid" 2>/dev/null || true; done
  rm -rf "$work"
}

# Every TCP socket of the cluster's processes is on 127.0.0.1 (listening or connected).
check_loopback() {
  command -v ss >/dev/null || return 0
  local off
  off="$(ss -tanp 2>/dev/null | awk '/gcs_server|raylet|ray::/ {
    for (k = 4; k <= 5; k++) {
      a = $k; sub(/:[0-9*]+$/, "", a)
      if (a != "127.0.0.1" && a != "[::ffff:127.0.0.1]" && !(k == 5 && (a == "0.0.0.0" || a == "*" || a == "[::]"))) print $4, $5, $6
    }
  }')"
  [ -z "$off" ] || fail "Ray sockets off loopback: $off"
}

# A head and a second worker node, one CPU each, every node on 127.0.0.1 (SINEW_RAY_LOOPBACK=1:
# see sinew_ray_loopback.py).
start_cluster() {
  export SINEW_RAY_LOOPBACK=1 RAY_USAGE_STATS_ENABLED=0
  local port nodes
  port="$(python3 -c 'import socket; s=socket.socket(); s.bind(("127.0.0.1", 0)); print(s.getsockname()[1])')"
  address="127.0.0.1:$port"
  "$ray" start --head --block --node-ip-address 127.0.0.1 --port "$port" --num-cpus 1 \
    --include-dashboard false --disable-usage-stats --temp-dir "$work/ray-tmp" >"$work/head.log" 2>&1 &
  pids+=($!)
  for _ in $(seq 120); do
    "$ray" status --address "$address" >/dev/null 2>&1 && break
    kill -0 "${pids[0]}" 2>/dev/null || fail "the Ray head did not start: $(tail -3 "$work/head.log")"
    sleep 0.5
  done
  "$ray" start --block --address "$address" --node-ip-address 127.0.0.1 --num-cpus 1 \
    --disable-usage-stats >"$work/worker.log" 2>&1 &
  pids+=($!)
  nodes=0
  for _ in $(seq 120); do
    nodes="$("$ray" status --address "$address" 2>/dev/null | grep -c '^ 1 node_' || true)"
    [ "$nodes" -ge 2 ] && break
    kill -0 "${pids[1]}" 2>/dev/null || fail "the Ray worker node did not start: $(tail -3 "$work/worker.log")"
    sleep 0.5
  done
  [ "$nodes" -ge 2 ] || fail "the cluster has $nodes nodes, not 2"
  check_loopback
}
