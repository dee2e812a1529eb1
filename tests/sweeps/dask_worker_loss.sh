#!/usr/bin/env bash
# dask_worker_loss.sh SFX SWEEP: starts a real dask-scheduler and two dask-workers on
# 127.0.0.1, runs SWEEP with --engine dask, kills -9 one worker (with the render it is running)
# in the middle of a task, and checks that the sweep completes with every point stored exactly
# once. Everything it starts is killed on exit; every wait is bounded.
set -euo pipefail
sfx=$1 sweep=$2
work=$(mktemp -d "${TMPDIR:-/tmp}/sfx-dask-test.XXXXXX")
pids=()
cleanup() {
  # Each process was started as its own process group (setsid): kill the groups, children too.
  for p in "${pids[@]}"; do kill -9 -- "-$p" 2>/dev/null || kill -9 "$p" 2>/dev/null || true; done
  if [ -n "${KEEP:-}" ]; then echo "kept $work"; else rm -rf "$work"; fi
}
trap cleanup EXIT
. "$(dirname "$0")/test_lib.sh"

port=$(/usr/bin/python3 -c 'import socket; s = socket.socket(); s.bind(("127.0.0.1", 0)); print(s.getsockname()[1])')
scheduler="tcp://127.0.0.1:$port"
setsid /usr/bin/dask-scheduler --host 127.0.0.1 --port "$port" --no-dashboard \
  >"$work/scheduler.log" 2>&1 &
pids+=($!)
wait_for 60 grep -q "Scheduler at" "$work/scheduler.log" || fail "scheduler did not start"
for i in 1 2; do
  # --no-nanny: the worker is this process, so kill -9 takes it down like a lost machine.
  setsid /usr/bin/dask-worker "$scheduler" --host 127.0.0.1 --nthreads 1 --no-nanny \
    --no-dashboard --local-directory "$work/w$i" --death-timeout 60 >"$work/worker$i.log" 2>&1 &
  pids+=($!)
  eval "worker$i=$!"
done
wait_for 60 grep -q "Registered to" "$work/worker1.log" || fail "worker 1 did not register"
wait_for 60 grep -q "Registered to" "$work/worker2.log" || fail "worker 2 did not register"

total=$("$sfx" sweep "$sweep" --dry-run --json | /usr/bin/python3 -c 'import json, sys; print(json.load(sys.stdin)["points"])')
setsid "$sfx" sweep "$sweep" --store "$work/results.db" --engine dask --scheduler "$scheduler" \
  >"$work/sweep.log" 2>&1 &
sweep_pid=$!
pids+=($sweep_pid)

# Kill worker 1 while it runs a group (its `sfx run-group` child exists), with that child.
busy() { pgrep -g "$worker1" -f "run-group" >/dev/null; }
wait_for 120 busy || fail "worker 1 never ran a group"
kill -9 -- "-$worker1"
echo "killed worker 1 (pid $worker1) during a task"

wait_for 240 bash -c "! kill -0 $sweep_pid 2>/dev/null" || fail "sweep did not finish in 240 s"
wait "$sweep_pid" || fail "sweep exited with status $?"

rows=$(sqlite3 "$work/results.db" "SELECT count(*) FROM points")
keys=$(sqlite3 "$work/results.db" "SELECT count(DISTINCT key) FROM points")
indices=$(sqlite3 "$work/results.db" "SELECT count(DISTINCT point_index) FROM points")
[ "$rows" = "$total" ] || fail "expected $total rows, found $rows"
[ "$keys" = "$total" ] || fail "expected $total distinct keys, found $keys"
[ "$indices" = "$total" ] || fail "expected $total distinct point indices, found $indices"
grep -q "Removing worker\|Remove worker" "$work/scheduler.log" || fail "the scheduler never lost a worker"
echo "PASS: $rows of $total points stored exactly once after losing a worker"
