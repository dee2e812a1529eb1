#!/usr/bin/env bash
# expect.sh CODE PATTERN COMMAND...: runs COMMAND, passes iff it exits with CODE and its output
# (stdout and stderr) matches the extended regular expression PATTERN.
set -u
code=$1 pattern=$2
shift 2
output=$("$@" 2>&1)
actual=$?
if [ "$actual" != "$code" ]; then
  printf 'expected exit %s, got %s from: %s\n%s\n' "$code" "$actual" "$*" "$output"
  exit 1
fi
if ! grep -Eq -- "$pattern" <<<"$output"; then
  printf 'output of %s does not match /%s/:\n%s\n' "$*" "$pattern" "$output"
  exit 1
fi
exit 0
