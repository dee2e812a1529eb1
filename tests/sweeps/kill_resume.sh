#!/usr/bin/env bash
# kill_resume.sh SFX SWEEP [in-commit]: starts `sfx sweep` in the background, kills it with
# SIGKILL once the store holds at least one row but the sweep is not done, re-runs it, and
# checks with sqlite3 that every point is stored exactly once and the store is intact; a third
# run must find nothing to do. With in-commit, the kill lands inside the store's write
# transaction (held open by the test-only SFX_TEST_HOLD_COMMIT_MS), after a first row is
# committed. Every wait is bounded; whatever it started is killed on exit.
set -euo pipefail
sfx=$1 sweep=$2 mode=${3:-}
. "$(dirname "$0")/test_lib.sh"
make_work sfx-kill-test
db="$work/results.db"
rows() { [ -s "$db" ] && sqlite3 "$db" "SELECT count(*) FROM points" 2>/dev/null || echo 0; }

read -r total groups < <("$sfx" sweep "$sweep" --dry-run --json |
  /usr/bin/python3 -c 'import json, sys; d = json.load(sys.stdin); print(d["points"], d["groups"])')
# One group at a time, so that rows arrive one group after another.
hold=
[ "$mode" = in-commit ] && hold=20000
SFX_TEST_HOLD_COMMIT_MS=$hold setsid "$sfx" sweep "$sweep" --store "$db" --jobs 1 >"$work/first.log" 2>&1 &
pid=$!
if [ "$mode" = in-commit ]; then
  # The first group's rows commit after 20 s; the kill lands while the second's are held uncommitted.
  second_write() { [ "$(grep -c '^sfx-test: inside the write transaction' "$work/first.log")" -ge 2 ]; }
  wait_for 200 second_write || fail "no second write transaction began in 200 s"
  held=$(grep '^sfx-test: inside the write transaction' "$work/first.log" | tail -1 | awk '{print $NF}')
else
  has_rows() { [ "$(rows)" -ge 1 ]; }
  wait_for 120 has_rows || fail "no row was stored in 120 s"
fi
kill -9 "$pid" 2>/dev/null || fail "the sweep had already finished: nothing was interrupted"
wait "$pid" 2>/dev/null && fail "the sweep was not killed" || true
# Its `sfx run-group` child dies with it (PR_SET_PDEATHSIG), leaving no orphan render.
orphan() { pgrep -f "run-group --parent-pid $pid" >/dev/null; }
no_orphan() { ! orphan; }
wait_for 10 no_orphan || fail "the killed sweep left its render running"
pid=
before=$(rows)
[ "$before" -lt "$total" ] || fail "all $total points were stored before the kill"
if [ "$mode" = in-commit ]; then
  # A group's rows are one transaction: the first group's are all stored, the held one's none.
  per_group=$(( total / groups ))
  [ "$before" = "$per_group" ] || fail "expected exactly the first group's $per_group rows committed, found $before"
  [ "$(sqlite3 "$db" "SELECT count(*) FROM points WHERE key='$held'")" = 0 ] ||
    fail "a row whose transaction was killed is stored"
  [ "$(sqlite3 "$db" "PRAGMA integrity_check")" = ok ] || fail "integrity check failed right after the kill"
  echo "killed the sweep inside the write transaction of $held"
fi
echo "killed the sweep with $before of $total points stored"

"$sfx" sweep "$sweep" --store "$db" >"$work/second.log" 2>&1 || fail "the re-run failed"
grep -q "$before already stored" "$work/second.log" || fail "the re-run did not skip the $before stored points"
[ "$(sqlite3 "$db" "PRAGMA integrity_check")" = ok ] || fail "store integrity check failed"
[ "$(sqlite3 "$db" "SELECT count(*) FROM points")" = "$total" ] || fail "expected $total rows"
[ "$(sqlite3 "$db" "SELECT count(DISTINCT key) FROM points")" = "$total" ] || fail "duplicated keys"
[ "$(sqlite3 "$db" "SELECT count(DISTINCT point_index) FROM points")" = "$total" ] || fail "missing points"
[ "$(sqlite3 "$db" "SELECT count(*) FROM points WHERE fps IS NULL OR fps <= 0")" = 0 ] || fail "rows without fps"

"$sfx" sweep "$sweep" --store "$db" >"$work/third.log" 2>&1 || fail "the third run failed"
grep -q "^0 points run, $total already stored" "$work/third.log" || fail "the third run ran points again"
echo "PASS: every one of $total points stored exactly once after kill -9 and a re-run"
