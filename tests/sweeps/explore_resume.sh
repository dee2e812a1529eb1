#!/usr/bin/env bash
# explore_resume.sh SFX: `sfx explore` with the real Optuna study and results store.
# 1. Store reuse: a sweep of the explore's whole space at its screen fidelity first; the
#    exhaustive explore then runs no point, and a search runs only its confirmation points.
# 2. Resume: an explore killed (SIGKILL, with its children) once it has stored points is re-run;
#    it finishes its budget, every point is stored once, the points stored before the kill are
#    not run again, and a third run runs nothing and prints the same front; a fourth with a
#    larger budget goes on from the 6 configurations screened.
set -euo pipefail
sfx=$1
src=$(cd "$(dirname "$0")/../.." && pwd)
. "$(dirname "$0")/test_lib.sh"
make_work sfx-explore-test
field() { /usr/bin/python3 -c 'import json, sys; d = json.load(open(sys.argv[1])); print(eval(sys.argv[2]))' "$@"; }

# 4 widths x 3 unit counts = 12 configurations on two scenes at 16x16.
cat > "$work/t.yaml" <<YAML
version: 1
name: t
hw: $src/hw_model/presets/gr08.hw.yaml
workload: {res: 16x16, spp: 1, tile: 8}
workloads:
  - {scene: cornell, weight: 2}
  - {scene: furnace}
knobs:
  hw.simd.width: [4, 8, 16, 32]
  hw.simd.units: [1, 2, 4]
objectives: {fps: maximize, area_mm2: minimize}
constraints: {area_mm2: {max: 100}}
budget: {evaluations: 6}
search: {sampler: tpe, seed: 3, batch: 2}
YAML
cat > "$work/t.sweep.yaml" <<YAML
version: 1
hw: $src/hw_model/presets/gr08.hw.yaml
workload: {scene: cornell, res: 16x16, spp: 1, tile: 8}
fidelity: analytic
axes:
  workload.scene: [cornell, furnace]
  hw.simd.width: [4, 8, 16, 32]
  hw.simd.units: [1, 2, 4]
YAML

# 1. Store reuse.
reuse="$work/reuse.db"
"$sfx" sweep "$work/t.sweep.yaml" --store "$reuse" >"$work/sweep.log" 2>&1 || fail "the sweep failed"
"$sfx" explore "$work/t.yaml" --store "$reuse" --exhaustive --json >"$work/grid.json" 2>"$work/grid.log" ||
  fail "the exhaustive explore failed"
[ "$(field "$work/grid.json" 'd["points_run"]')" = 0 ] || fail "the exhaustive explore ran points the sweep had stored"
[ "$(field "$work/grid.json" 'len(d["screened"])')" = 12 ] || fail "the exhaustive explore did not screen all 12"
"$sfx" explore "$work/t.yaml" --store "$reuse" --json >"$work/search.json" 2>"$work/search.log" ||
  fail "the search failed"
front=$(field "$work/search.json" 'len(d["screen_front"])')
[ "$(field "$work/search.json" 'd["evaluations"]')" = 6 ] || fail "the search did not spend its budget of 6"
[ "$(field "$work/search.json" 'd["points_run"]')" = $((2 * front)) ] ||
  fail "the search ran more than its $front front configurations' confirmation points"
[ "$(sqlite3 "$reuse" "SELECT count(*) FROM explore_configs WHERE explore = 't' AND stage = 'screen'")" = 6 ] ||
  fail "the store does not hold the 6 screened configurations"
[ "$(sqlite3 "$reuse" "SELECT count(*) FROM explore_configs WHERE explore = 't/grid'")" = 12 ] ||
  fail "the store does not hold the grid's 12 configurations"
echo "store reuse: the exhaustive explore ran 0 points after the sweep; the search ran only its $((2 * front)) confirmation points"

# 2. Resume after kill -9.
db="$work/results.db"
rows() { [ -s "$db" ] && sqlite3 "$db" "SELECT count(*) FROM points" 2>/dev/null || echo 0; }
setsid "$sfx" explore "$work/t.yaml" --store "$db" --jobs 1 >"$work/first.log" 2>&1 &
pid=$!
has_rows() { [ "$(rows)" -ge 2 ]; }
wait_for 120 has_rows || fail "no point was stored in 120 s"
kill -9 -- "-$pid" 2>/dev/null || fail "the explore had already finished: nothing was interrupted"
wait "$pid" 2>/dev/null && fail "the explore was not killed" || true
pid=
before=$(rows)
[ "$(sqlite3 "$db" "PRAGMA integrity_check")" = ok ] || fail "integrity check failed right after the kill"
"$sfx" explore "$work/t.yaml" --store "$db" --json >"$work/second.json" 2>"$work/second.log" || fail "the re-run failed"
[ "$(field "$work/second.json" 'd["evaluations"]')" = 6 ] || fail "the resumed explore did not finish its budget"
after=$(rows)
ran=$(field "$work/second.json" 'd["points_run"]')
[ $((before + ran)) = "$after" ] || fail "$before rows before, $ran run, $after after: a point ran twice or went missing"
[ "$(sqlite3 "$db" "SELECT count(DISTINCT key) FROM points")" = "$after" ] || fail "duplicated keys"
"$sfx" explore "$work/t.yaml" --store "$db" --json >"$work/third.json" 2>"$work/third.log" || fail "the third run failed"
[ "$(field "$work/third.json" 'd["points_run"]')" = 0 ] || fail "the third run ran points again"
[ "$(field "$work/second.json" 'sorted(f["config"] for f in d["front"])')" = \
  "$(field "$work/third.json" 'sorted(f["config"] for f in d["front"])')" ] || fail "the third run's front differs"
# A larger budget goes on with the same search: 2 more configurations screened, the 6 kept.
"$sfx" explore "$work/t.yaml" --store "$db" --budget 8 --json >"$work/more.json" 2>"$work/more.log" || fail "the run with --budget 8 failed"
[ "$(field "$work/more.json" 'd["evaluations"]')" = 8 ] || fail "--budget 8 did not screen 8 configurations"
[ "$(sqlite3 "$db" "SELECT count(*) FROM explore_configs WHERE explore = 't' AND stage = 'screen'")" = 8 ] ||
  fail "--budget 8 did not keep the first 6 configurations"
echo "PASS: killed with $before points stored, resumed with $ran more ($after in all, each once); a third run ran nothing; --budget 8 went on"
