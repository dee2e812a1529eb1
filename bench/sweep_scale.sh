#!/usr/bin/env bash
# sweep_scale.sh [SFX]: the sweep machinery at scale, local engine against a local Dask cluster.
# Runs bench/scale-analytic.sweep.yaml (20,032 analytic points in 313 renders) and
# bench/scale-sampled.sweep.yaml (104 sampled points in 13 renders) with the local engine into
# one store, then with --engine dask on a scheduler and 3 workers (one thread each) on
# 127.0.0.1 into another, killing one worker (kill -9, with the render it runs) once half of the
# analytic points are stored. Checks that every point is stored exactly once in both stores and
# that a second run finds nothing to do, and prints points per second of each engine.
# Everything it starts is killed on exit. About 4 minutes on a 2-core machine.
set -euo pipefail
cd "$(dirname "$0")/.."
sfx=$(realpath "${1:-build/sfx}")
analytic=bench/scale-analytic.sweep.yaml
sampled=bench/scale-sampled.sweep.yaml
work=$(mktemp -d "${TMPDIR:-/tmp}/sfx-scale.XXXXXX")
pids=()
cleanup() {
  for p in "${pids[@]}"; do kill -9 -- "-$p" 2>/dev/null || kill -9 "$p" 2>/dev/null || true; done
  if [ -n "${KEEP:-}" ]; then echo "kept $work"; else rm -rf "$work"; fi
}
trap cleanup EXIT
. tests/sweeps/test_lib.sh
points() { "$sfx" sweep "$1" --dry-run --json | /usr/bin/python3 -c 'import json, sys; print(json.load(sys.stdin)["points"])'; }
rows() { [ -s "$1" ] && sqlite3 "$1" "SELECT count(*) FROM points" 2>/dev/null || echo 0; }
total=$(( $(points "$analytic") + $(points "$sampled") ))

# Every point once: rows, distinct keys and distinct (sweep, point index) all equal the total,
# and a second run of both sweeps runs nothing.
check_store() {
  local db=$1; shift
  [ "$(rows "$db")" = "$total" ] || fail "$db: expected $total rows, found $(rows "$db")"
  [ "$(sqlite3 "$db" "SELECT count(DISTINCT key) FROM points")" = "$total" ] || fail "$db: duplicated keys"
  [ "$(sqlite3 "$db" "SELECT count(*) FROM (SELECT DISTINCT sweep, point_index FROM points)")" = "$total" ] ||
    fail "$db: missing points"
  [ "$(sqlite3 "$db" "SELECT count(*) FROM points WHERE fps IS NULL OR fps <= 0 OR \"error.relative\" < 0")" = 0 ] ||
    fail "$db: rows without fps or without a stated error"
  for s in "$analytic" "$sampled"; do
    "$sfx" sweep "$s" --store "$db" "$@" >"$work/again.log" 2>&1 || fail "the second run of $s failed"
    grep -q "^0 points run" "$work/again.log" || fail "the second run of $s ran points again"
  done
}

start=$SECONDS
for s in "$analytic" "$sampled"; do
  "$sfx" sweep "$s" --store "$work/local.db" >"$work/local.log" 2>&1 || fail "local sweep $s failed"
done
local_seconds=$((SECONDS - start))
check_store "$work/local.db"

port=$(/usr/bin/python3 -c 'import socket; s = socket.socket(); s.bind(("127.0.0.1", 0)); print(s.getsockname()[1])')
scheduler="tcp://127.0.0.1:$port"
setsid /usr/bin/dask-scheduler --host 127.0.0.1 --port "$port" --no-dashboard >"$work/scheduler.log" 2>&1 &
pids+=($!)
disown  # killed on purpose at the end: no "Killed" line from the shell
wait_for 60 grep -q "Scheduler at" "$work/scheduler.log" || fail "scheduler did not start"
for i in 1 2 3; do
  setsid /usr/bin/dask-worker "$scheduler" --host 127.0.0.1 --nthreads 1 --no-nanny \
    --no-dashboard --local-directory "$work/w$i" --death-timeout 60 >"$work/worker$i.log" 2>&1 &
  pids+=($!)
  eval "worker$i=$!"
  disown
done
for i in 1 2 3; do
  wait_for 60 grep -q "Registered to" "$work/worker$i.log" || fail "worker $i did not register"
done
start=$SECONDS
setsid "$sfx" sweep "$analytic" --store "$work/dask.db" --engine dask --scheduler "$scheduler" \
  >"$work/dask.log" 2>&1 &
sweep_pid=$!
pids+=($sweep_pid)
half() { [ "$(rows "$work/dask.db")" -ge $(( $(points "$analytic") / 2 )) ]; }
wait_for 600 half || fail "half of the analytic points were not stored in 600 s"
kill -9 -- "-$worker2"
echo "killed worker 2 (pid $worker2) with $(rows "$work/dask.db") points stored"
wait_for 900 bash -c "! kill -0 $sweep_pid 2>/dev/null" || fail "the Dask sweep did not finish"
wait "$sweep_pid" || fail "the Dask sweep exited with status $?"
"$sfx" sweep "$sampled" --store "$work/dask.db" --engine dask --scheduler "$scheduler" \
  >>"$work/dask.log" 2>&1 || fail "the sampled Dask sweep failed"
dask_seconds=$((SECONDS - start))
grep -q "Removing worker\|Remove worker" "$work/scheduler.log" || fail "the scheduler never lost a worker"
check_store "$work/dask.db" --engine dask --scheduler "$scheduler"

echo "$total points ($(points "$analytic") analytic, $(points "$sampled") sampled), every one stored once by each engine"
echo "local engine ($(nproc) processes): ${local_seconds} s, $((total / (local_seconds > 0 ? local_seconds : 1))) points/s"
echo "Dask, 3 workers, one killed midway: ${dask_seconds} s, $((total / (dask_seconds > 0 ? dask_seconds : 1))) points/s"
