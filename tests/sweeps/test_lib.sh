# Helpers sourced by the sweep shell tests; they expect $work (the test's temporary folder).

# fail MESSAGE: prints the message and the tail of every log in $work, then exits 1.
fail() {
  echo "FAIL: $*"
  for f in "$work"/*.log; do echo "== $f"; tail -n 30 "$f"; done
  exit 1
}

# wait_for SECONDS COMMAND...: polls COMMAND every 0.1 s until it succeeds or time runs out.
wait_for() {
  local deadline=$((SECONDS + $1)); shift
  until "$@"; do [ $SECONDS -lt $deadline ] || return 1; sleep 0.1; done
}
