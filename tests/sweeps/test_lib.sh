# Helpers sourced by the sweep shell tests; they expect $work (the test's temporary folder,
# make_work below makes one).

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

# make_work PREFIX: sets $work to a fresh temporary folder and $pid to empty; on exit kills the
# process group of $pid (a command under test started with setsid) if it is set, then removes
# $work (KEEP=1 keeps it and says where).
make_work() {
  work=$(mktemp -d "${TMPDIR:-/tmp}/$1.XXXXXX")
  pid=
  trap cleanup_work EXIT
}
cleanup_work() {
  [ -z "$pid" ] || kill -9 -- "-$pid" 2>/dev/null || true
  if [ -n "${KEEP:-}" ]; then echo "kept $work"; else rm -rf "$work"; fi
}
