#!/usr/bin/env bash
# bad_input.sh SFX CASE: one class of adversarial input against the real binary. Each case
# checks the exit code (2), that the message names the file and line or the flag, and that
# nothing was written or changed. Runs in its own temporary directory.
set -uo pipefail
sfx=$1 case=$2
src=$(cd "$(dirname "$0")/../.." && pwd)
gr08=$src/hw_model/presets/gr08.hw.yaml
slow=$src/tests/sweeps/slow.sweep.yaml
work=$(mktemp -d "${TMPDIR:-/tmp}/sfx-bad-input.XXXXXX")
trap 'chmod -R u+w "$work" 2>/dev/null; rm -rf "$work"' EXIT
cd "$work"
fail() { echo "FAIL ($case): $*"; exit 1; }
# expect CODE PATTERN COMMAND...: exit code and output (ERE); at most 60 s, never blocking.
expect() {
  local code=$1 pattern=$2; shift 2
  local out actual
  out=$(timeout 60 "$@" 2>&1 </dev/null); actual=$?
  [ "$actual" = "$code" ] || fail "expected exit $code, got $actual from: $*"$'\n'"$out"
  grep -Eq -- "$pattern" <<<"$out" || fail "output of $* does not match /$pattern/:"$'\n'"$out"
}
scene_with_mesh() {  # a scene file whose only object is the mesh $1
  printf 'version: 1\ncamera: {eye: [0, 0, 5], look_at: [0, 0, 0]}\nmaterials: [{name: a, kind: lambertian}]\nobjects:\n  - {type: mesh, material: a, file: %s}\n' "$1" > m.scene.yaml
}

case $case in
numbers)  # range-checked, never wrapped, clamped, read as octal/hex or mapped to "unset"
  for args in "--seed -1" "--seed 99999999999999999999999" "--depth -1" "--depth 1001" \
              "--spp 0x10" "--spp 0" "--threads 4294967296" "--threads -2" "--seed 1e3"; do
    flag=${args%% *}
    expect 2 "$flag" "$sfx" render cornell --res 8x8 -o out.png $args
  done
  expect 2 "--jobs" "$sfx" sweep "$slow" --dry-run --jobs -1
  # Counts of threads and jobs have an upper bound too (a typo must not start a million threads).
  expect 2 "^sfx: error: command line: --threads: .*1024" "$sfx" render cornell --res 8x8 -o out.png --threads 5000
  expect 2 "--jobs: .*1024" "$sfx" sweep "$slow" --dry-run --jobs 5000
  expect 2 "^sfx: error: command line: --spp: expected an integer in \[1, 1048576\], got '0'$" \
    "$sfx" render cornell --res 8x8 -o out.png --spp 0
  expect 2 "--rays" "$sfx" validate cornell --rays 18446744073709551616
  expect 2 "--ulps" "$sfx" validate cornell --against embree --ulps nan
  expect 2 "--strata" "$sfx" simulate "$gr08" --scene cornell --res 8x8 --fidelity sampled --strata -1
  [ ! -e out.png ] || fail "a rejected command wrote out.png"
  # A leading zero is decimal, not octal: --depth 010 renders at depth 10.
  expect 0 "depth 10" "$sfx" render cornell --res 8x8 --spp 1 --depth 010 -o out.png
  ;;
mesh_nonfinite)  # rejected even where assimp alone would read a number (1.#INF as 1)
  for tok in nan -inf 1e39 1.#INF 1.#QNAN 0x1p200; do
    printf 'v %s 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n' "$tok" > t.obj
    scene_with_mesh t.obj
    expect 2 "m.scene.yaml:5: objects\[0\]\.file: .*(not a finite number|non-finite)" "$sfx" scene-info m.scene.yaml
  done
  printf 'ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\nproperty float y\nproperty float z\nelement face 1\nproperty list uchar int vertex_indices\nend_header\n0 0 0\n1 1.#INF 0\n0 1 0\n3 0 1 2\n' > t.ply
  scene_with_mesh t.ply
  expect 2 "objects\[0\]\.file: .*line 11: '1.#INF' is not a finite number" "$sfx" scene-info m.scene.yaml
  # Finite coordinates a transform moves out of float range.
  printf 'v 1e38 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n' > t.obj
  printf 'version: 1\ncamera: {eye: [0, 0, 5], look_at: [0, 0, 0]}\nmaterials: [{name: a, kind: lambertian}]\nobjects:\n  - {type: mesh, material: a, file: t.obj, transform: {scale: 1e10}}\n' > m.scene.yaml
  expect 2 "m.scene.yaml:5: objects\[0\]\.transform: .*out of float range" "$sfx" scene-info m.scene.yaml
  ;;
not_regular)  # a FIFO, a device or a directory is refused at once, never opened blocking
  mkfifo fifo.hw.yaml fifo.scene.yaml fifo.sweep.yaml fifo.obj fifo.db
  mkdir dir.hw.yaml
  expect 2 "fifo.hw.yaml: .*a FIFO" "$sfx" simulate fifo.hw.yaml --scene cornell --res 8x8
  expect 2 "dir.hw.yaml: .*a directory" "$sfx" simulate dir.hw.yaml --scene cornell --res 8x8
  expect 2 "fifo.scene.yaml: .*a FIFO" "$sfx" scene-info ./fifo.scene.yaml
  expect 2 "fifo.sweep.yaml: .*a FIFO" "$sfx" sweep fifo.sweep.yaml --dry-run
  expect 2 "/dev/zero: .*character device" "$sfx" sweep /dev/zero --dry-run
  expect 2 "fifo.db: .*a FIFO" "$sfx" sweep "$slow" --store fifo.db
  expect 2 "fifo.db: .*a FIFO" "$sfx" compare --store fifo.db --a hw.simd.width=8 --b hw.simd.width=16
  mkdir dir.db
  expect 2 "dir.db: .*a directory" "$sfx" report dir.db -o report
  scene_with_mesh fifo.obj
  expect 2 "objects\[0\]\.file: .*a FIFO" "$sfx" scene-info m.scene.yaml
  ;;
second_document)  # a second YAML document is refused, not half read
  { cat "$gr08"; printf -- '---\nsimd: {width: 4}\n'; } > two.hw.yaml
  line=$(($(wc -l < "$gr08") + 2))
  expect 2 "two.hw.yaml:$line: a second YAML document" "$sfx" simulate two.hw.yaml --scene cornell --res 8x8
  { cat "$src/workloads/scenes/cornell.scene.yaml"; printf -- '---\n'; } > two.scene.yaml
  expect 2 "two.scene.yaml:[0-9]+: a second YAML document" "$sfx" scene-info ./two.scene.yaml
  { cat "$slow" | sed "s|^hw: .*|hw: $gr08|"; printf -- '---\nname: other\n'; } > two.sweep.yaml
  expect 2 "two.sweep.yaml:[0-9]+: a second YAML document" "$sfx" sweep two.sweep.yaml --dry-run
  ;;
non_scalar_key)  # a list or a map as a key: exit 2 naming file, line and key
  printf 'version: 1\n? [a]\n: 1\n' > k.hw.yaml
  expect 2 "k.hw.yaml:2: \[a\]: a key must be a plain scalar" "$sfx" simulate k.hw.yaml --scene cornell --res 8x8
  printf 'version: 1\nsimd:\n  ? {x: 1}\n  : 2\n' > k2.hw.yaml
  expect 2 "k2.hw.yaml:3: simd\.\{x: 1\}: a key must be a plain scalar" "$sfx" simulate k2.hw.yaml --scene cornell --res 8x8
  printf 'version: 1\ncamera: {eye: [0, 0, 5], look_at: [0, 0, 0]}\nmaterials: [{name: a, kind: lambertian, ? [k] : 1}]\nobjects: []\n' > k.scene.yaml
  expect 2 "k.scene.yaml:3: materials\[0\]\.\[k\]: a key must be a plain scalar" "$sfx" scene-info ./k.scene.yaml
  ;;
outputs)  # checked before the work, naming the flag; nothing half-written
  expect 2 "--output: cannot write 'nodir/x.png': directory 'nodir' does not exist" \
    "$sfx" render cornell --res 8x8 -o nodir/x.png
  mkdir x.pfm  # the PFM beside the PNG cannot be written: the PNG must not appear either
  expect 2 "--output \(the PFM beside it\): cannot write 'x.pfm': it is a directory" \
    "$sfx" render cornell --res 8x8 -o x.png
  [ ! -e x.png ] || fail "x.png was written although x.pfm could not be"
  expect 2 "--trace: cannot write 'nodir/t.trc'" \
    "$sfx" render cornell --res 8x8 --tracer stream --trace nodir/t.trc -o y.png
  [ ! -e y.png ] && [ ! -e y.pfm ] || fail "an output was written although --trace could not be"
  expect 2 "--plot: cannot write 'nodir/p.png'" \
    "$sfx" accuracy "$gr08" --scene cornell --plot nodir/p.png
  ls -A | grep -q partial && fail "a temporary file was left: $(ls -A)"
  expect 0 "wrote" "$sfx" render cornell --res 8x8 --spp 1 -o ok.png
  [ -s ok.png ] && [ -s ok.pfm ] || fail "ok.png and ok.pfm were not both written"
  ls -A | grep -q partial && fail "a temporary file was left: $(ls -A)"
  ;;
sweep_outputs)  # --csv and --store are checked before the sweep runs
  expect 2 "--csv: cannot write 'nodir/x.csv'" "$sfx" sweep "$slow" --store s.db --csv nodir/x.csv
  [ ! -e s.db ] || fail "the store was created although --csv cannot be written"
  expect 2 "--store: cannot write 'nodir/s.db'" "$sfx" sweep "$slow" --store nodir/s.db
  mkdir csvdir
  expect 2 "--csv: cannot write 'csvdir': it is a directory" "$sfx" sweep "$slow" --store s.db --csv csvdir
  [ ! -e s.db ] || fail "the store was created although --csv cannot be written"
  ;;
foreign_store)  # an SQLite file that is not an sfx store is refused and left untouched
  sqlite3 other.db "CREATE TABLE t(x); INSERT INTO t VALUES (1);"
  before=$(sha256sum < other.db)
  expect 2 "other.db: --store: an SQLite database but not an sfx results store \(its tables: t" \
    "$sfx" sweep "$slow" --store other.db --set workload.res=16x16 --set fidelity=analytic
  expect 2 "not an sfx results store" "$sfx" compare --store other.db --a hw.simd.width=8 --b hw.simd.width=16
  [ "$before" = "$(sha256sum < other.db)" ] || fail "other.db was changed"
  [ ! -e other.db-wal ] || fail "a write-ahead log was added to other.db"
  printf 'not a database at all\n' > junk.db
  expect 2 "junk.db: --store: not a usable results store: .*not a database" "$sfx" sweep "$slow" --store junk.db
  [ "$(cat junk.db)" = "not a database at all" ] || fail "junk.db was changed"
  expect 2 "missing.db: --store: no such results store" "$sfx" compare --store missing.db --a hw.simd.width=8 --b hw.simd.width=16
  ;;
read_only_store)  # a finished store in a read-only directory can still be compared and reported
  mkdir ro
  "$sfx" sweep "$slow" --store ro/s.db --set workload.res=16x16 --set workload.spp=1 \
    --set fidelity=analytic >sweep.log 2>&1 || { cat sweep.log; fail "the sweep failed"; }
  chmod -R a+rX "$work"; chmod 555 ro
  as=()  # root ignores directory permissions: read as nobody
  if [ "$(id -u)" = 0 ]; then as=(setpriv --reuid=nobody --regid=nogroup --clear-groups); fi
  "${as[@]}" sh -c 'touch ro/probe' 2>/dev/null && fail "the directory is writable: cannot test"
  expect 0 "means over 8 input combinations" \
    "${as[@]}" "$sfx" compare --store ro/s.db --a hw.simd.width=8 --b hw.simd.width=16
  chmod 777 "$work"
  expect 0 "" "${as[@]}" "$sfx" report ro/s.db -o "$work/report"
  [ -s "$work/report/index.html" ] || fail "no report was written"
  ls ro | grep -qv '^s.db$' && fail "files were added to the read-only directory: $(ls ro)"
  ;;
sweep_cap)  # expansion is bounded by a guard the user can raise, and says so at once
  printf 'version: 1\nhw: %s\nworkload: {scene: cornell}\nfidelity: analytic\naxes:\n  workload.seed: {from: 0, to: 999, step: 1}\n  workload.spp: {from: 1, to: 1001, step: 1}\n' "$gr08" > big.sweep.yaml
  start=$SECONDS
  expect 2 "big.sweep.yaml:6: axes: more than 1000000 points \(sfx sweep --max-points raises the limit\)" "$sfx" sweep big.sweep.yaml --dry-run
  [ $((SECONDS - start)) -le 5 ] || fail "refusing took $((SECONDS - start)) s"
  expect 2 "big.sweep.yaml:6: axes: more than 5000 points" "$sfx" sweep big.sweep.yaml --dry-run --max-points 5000
  expect 2 "--max-points" "$sfx" sweep big.sweep.yaml --dry-run --max-points 0
  printf 'version: 1\nhw: %s\nworkload: {scene: cornell}\naxes:\n  workload.seed: {from: 0, to: 1e15, step: 1}\n' "$gr08" > wide.sweep.yaml
  expect 2 "wide.sweep.yaml:5: axes.workload.seed: (more than 1000000 values|expected)" "$sfx" sweep wide.sweep.yaml --dry-run
  ;;
generator_budget)  # parameters each in range that together ask too much: refused up front
  printf 'version: 1\ncamera: {eye: [0, 0, 5], look_at: [0, 0, 0]}\nmaterials: [{name: a, kind: lambertian}]\nobjects:\n  - {type: generator, generator: temple, rubble_stones: 1000000, rubble_detail: 6,\n     materials: {stone: a, relief: a, floor: a, sky: a, sanctuary: a}}\n' > g.scene.yaml
  start=$SECONDS
  expect 2 "g.scene.yaml:5: objects\[0\]: generator temple would make more than 33554432 primitives.*rubble_stones: 1000000, rubble_detail: 6" \
    "$sfx" scene-info ./g.scene.yaml
  [ $((SECONDS - start)) -le 10 ] || fail "refusing took $((SECONDS - start)) s"
  ;;
unknown_command)  # named, with the nearest command
  expect 2 "unknown command 'rendr' \(did you mean 'render'\?\)" "$sfx" rendr cornell
  expect 2 "unknown command 'sweeep' \(did you mean 'sweep'\?\)" "$sfx" sweeep x.sweep.yaml
  expect 2 "unknown command 'xyzzy'; see sfx --help" "$sfx" xyzzy
  ;;
*) fail "no such case" ;;
esac
echo "PASS: $case"
