#!/usr/bin/env bash
# kill_resume.sh SFX SWEEP: starts `sfx sweep` in the background, kills it with SIGKILL once
# the store holds at least one row but the sweep is not done, re-runs it, and checks with
# sqlite3 that every point is stored exactly once and the store is intact; a third run must
# find nothing to do. Every wait is bounded; whatever it started is killed on exit.
set -euo pipefail
sfx=$1 sweep=$2
work=$(mktemp -d "${TMPDIR:-/tmp}/sfx-kill-test.XXXXXX")
pid=
cleanup() {
  [ -z "$pid" ] || kill -9 -- "-$pid" 2>/dev/null || true
  if [ -n "${KEEP:-}" ]; then echo "kept $work"; else rm -rf "$work"; fi
}
trap cleanup EXIT
. "$(dirname "$0")/test_lib.sh"
db="$work/results.db"
rows() { [ -s "$db" ] && sqlite3 "$db" "SELECT count(*) FROM points" 2>/dev/null || echo 0; }

total=$("$sfx" sweep "$sweep" --dry-run --json | /usr/bin/python3 -c 'import json, sys; print(json.load(sys.stdin)["points"])')
# One group at a time, so that rows arrive one group after another.
setsid "$sfx" sweep "$sweep" --store "$db" --jobs 1 >"$work/first.log" 2>&1 &
pid=$!
has_rows() { [ "$(rows)" -ge 1 ]; }
wait_for 120 has_rows || fail "no row was stored in 120 s"
kill -9 "$pid" 2>/dev/null || fail "the sweep had already finished: nothing was interrupted"
wait "$pid" 2>/dev/null && fail "the sweep was not killed" || true
# Its `sfx run-group` child dies with it (PR_SET_PDEATHSIG), leaving no orphan render.
orphan() { pgrep -f "run-group --parent-pid $pid" >/dev/null; }
no_orphan() { ! orphan; }
wait_for 10 no_orphan || fail "the killed sweep left its render running"
pid=
before=$(rows)
[ "$before" -lt "$total" ] || fail "all $total points were stored before the kill"
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
