"""The Ray driver of `sinew batch MANIFEST --ray ADDRESS` (started by sinew, not by hand).

Connects to the Ray cluster at --address, then reads job names from stdin, one a line, and runs
each as a Ray task on some worker: the task calls `SINEW batch MANIFEST --job NAME`, which
runs that one job through the same library call as a local batch, and reports a JSON line.
As tasks finish, their results are printed on stdout, one JSON object a line:
{"name", "ok", "error", "seconds"}; sinew schedules, records and reports. End of stdin: no
more jobs; the driver exits once the submitted tasks are done.

A task whose worker process dies (killed, out of memory, node lost) is rerun by Ray up to
--max-retries times; a job that fails on its own returns its error and is not rerun. The
sinew process a task starts dies with its worker (PR_SET_PDEATHSIG), so a rerun never races a
stale run. Paths (the binary, the manifest, the files) must be the same on every node: one
machine, or shared storage mounted at one path.
"""

import argparse
import json
import os
import queue
import signal
import socket
import subprocess
import sys
import threading
import time

import ray


@ray.remote(num_cpus=1)
def run_job(sinew, manifest, name, log_dir):
    """Runs one job on this worker; returns its result line as a dict."""
    if log_dir:
        # One line per attempt (tests check that a killed task ran again elsewhere).
        with open(os.path.join(log_dir, "attempts.log"), "a") as log:
            log.write(f"{name}\t{os.getpid()}\n")

    def die_with_parent():
        import ctypes

        ctypes.CDLL("libc.so.6", use_errno=True).prctl(1, signal.SIGKILL)  # PR_SET_PDEATHSIG

    started = time.monotonic()
    proc = subprocess.run(
        [sinew, "batch", manifest, "--job", name],
        stdout=subprocess.PIPE,
        stderr=subprocess.PIPE,
        text=True,
        preexec_fn=die_with_parent,
    )
    wall = time.monotonic() - started
    for line in reversed(proc.stdout.splitlines()):
        try:
            result = json.loads(line)
        except ValueError:
            continue
        if isinstance(result, dict) and result.get("name") == name:
            result["task_seconds"] = wall
            return result
    error = (proc.stderr.strip().splitlines() or [f"exit status {proc.returncode}"])[-1]
    return {"name": name, "ok": False, "error": error, "seconds": wall, "task_seconds": wall}


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--address", required=True)
    parser.add_argument("--sinew", required=True)
    parser.add_argument("--manifest", required=True)
    parser.add_argument("--max-retries", type=int, default=3)
    args = parser.parse_args()
    # Ray's own messages go to stderr; stdout carries only result lines.
    # Nothing listening there: say so at once (ray.init would wait for a minute).
    host, _, port = args.address.rpartition(":")
    try:
        socket.create_connection((host, int(port)), timeout=5).close()
    except (OSError, ValueError) as error:
        print(f"cannot connect to the Ray cluster at {args.address}: {error}", file=sys.stderr)
        sys.exit(2)
    try:
        ray.init(address=args.address, logging_level="ERROR", log_to_driver=False)
    except Exception as error:  # no cluster there, another Ray version, …
        lines = str(error).strip().splitlines() or [type(error).__name__]
        print(f"cannot connect to the Ray cluster at {args.address}: {lines[0]}", file=sys.stderr)
        sys.exit(2)
    log_dir = os.environ.get("SINEW_RAY_LOG_DIR", "")
    names = queue.Queue()

    def read_stdin():
        for line in sys.stdin:
            if line.strip():
                names.put(line.strip())
        names.put(None)

    threading.Thread(target=read_stdin, daemon=True).start()
    task = run_job.options(max_retries=args.max_retries, retry_exceptions=False)
    pending = {}
    open_input = True
    while open_input or pending:
        # Submit what has come in.
        while True:
            try:
                name = names.get(timeout=0 if pending or not open_input else 0.5)
            except queue.Empty:
                break
            if name is None:
                open_input = False
                break
            ref = task.remote(args.sinew, args.manifest, name, log_dir)
            pending[ref] = name
        if not pending:
            continue
        done, _ = ray.wait(list(pending), num_returns=1, timeout=0.05)
        for ref in done:
            name = pending.pop(ref)
            try:
                result = ray.get(ref)
            except Exception as error:  # the retries ran out, or the cluster is gone
                message = str(error).strip().splitlines()
                result = {"name": name, "ok": False, "seconds": 0.0,
                          "error": "Ray: " + (message[0] if message else type(error).__name__)}
            print(json.dumps(result), flush=True)


if __name__ == "__main__":
    main()
