#!/usr/bin/python3
"""The Dask side of `sfx sweep --engine dask`: runs point groups on an existing Dask cluster.

stdin:  one JSON line per point group: {"group": i, "spec": {...}} (sfx run-group's input),
        read as the window (--window groups submitted and unfinished) has room, so a sweep of
        any size streams through a bounded client.
stdout: one JSON line per finished group, as groups finish, in any order:
        {"group": i, "rows": [...]}                 the rows `sfx run-group` printed
        {"group": i, "error": "...", "exit_code": n} the group failed (not retried if n == 2)

Each Dask task runs `SFX run-group` on its worker (the sfx binary must be at the same path
there: a shared file system or the same container image) and returns the rows; the workers
never touch the results store. A task whose worker dies is re-run by the scheduler on another
worker (up to distributed.scheduler.allowed-failures times); `sfx sweep` ignores a group's
rows after the first copy and the store's key makes any repeat a no-op.
"""

import argparse
import json
import os
import subprocess
import sys


def run_group(sfx, spec_line):
    """Runs one group on a worker. Input errors (exit 2) are results, not retried; any other
    failure raises so that Dask may retry it."""
    proc = subprocess.run(
        [sfx, "run-group", "--parent-pid", str(os.getpid())],
        input=spec_line,
        capture_output=True,
        text=True,
        env=dict(os.environ, SYSTEMC_DISABLE_COPYRIGHT_MESSAGE="1"),
    )
    if proc.returncode == 2:
        return {"error": proc.stderr.strip() or "sfx run-group: bad input", "exit_code": 2}
    if proc.returncode != 0:
        raise RuntimeError(
            "sfx run-group exited with status %d: %s" % (proc.returncode, proc.stderr.strip()[-2000:])
        )
    rows = [json.loads(line) for line in proc.stdout.splitlines() if line.startswith("{")]
    return {"rows": rows}


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--scheduler", required=True, help="tcp://HOST:PORT")
    parser.add_argument("--sfx", required=True, help="path of the sfx binary on the workers")
    parser.add_argument("--timeout", default="30s", help="time to reach the scheduler")
    parser.add_argument("--retries", type=int, default=2, help="re-runs of a failing group")
    parser.add_argument("--window", type=int, default=64, help="groups submitted and unfinished at most")
    args = parser.parse_args()

    try:
        from distributed import Client, as_completed
    except ImportError as e:
        sys.exit("dask_client: Dask is not installed (Debian: python3-distributed): %s" % e)

    try:
        client = Client(args.scheduler, timeout=args.timeout)
    except Exception as e:  # noqa: BLE001 - report any connection failure plainly
        sys.exit("dask_client: cannot reach the Dask scheduler at %s: %s" % (args.scheduler, e))

    futures = {}
    pending = as_completed()

    def submit_next():
        """Submits the next group from stdin; False at its end."""
        for line in sys.stdin:
            if not line.strip():
                continue
            g = json.loads(line)
            spec_line = json.dumps(g["spec"]) + "\n"
            # pure=False: two groups with equal specs are still two tasks; the key names the group.
            future = client.submit(run_group, args.sfx, spec_line, key="sfx-group-%d-%d" % (g["group"], os.getpid()),
                                   pure=False, retries=args.retries)
            futures[future] = g["group"]
            pending.add(future)
            return True
        return False

    while len(futures) < max(1, args.window) and submit_next():
        pass
    for future in pending:
        group = futures.pop(future)
        try:
            result = future.result()
        except Exception as e:  # noqa: BLE001 - KilledWorker, a task's RuntimeError, ...
            result = {"error": "%s: %s" % (type(e).__name__, e), "exit_code": 1}
        result["group"] = group
        sys.stdout.write(json.dumps(result) + "\n")
        sys.stdout.flush()
        submit_next()
    client.close()


if __name__ == "__main__":
    main()
