#!/usr/bin/env bash
# layering.sh can fail: on a copy of the tree, one forbidden include per rule must make it fail
# and name that rule, and the clean copy must pass.
set -euo pipefail
here="$(cd "$(dirname "$0")" && pwd)"
src="$here/../.."
tmp="$(mktemp -d)"
trap 'rm -rf "$tmp"' EXIT
copy() {
    rm -rf "$tmp/tree" && mkdir -p "$tmp/tree"
    for d in base workloads kernels hw_model; do cp -r "$src/$d" "$tmp/tree/$d"; done
}
copy
"$here/layering.sh" "$tmp/tree" > /dev/null || { echo "the clean copy fails"; exit 1; }
status=0
# breaks FILE INCLUDE RULE: adding `#include "INCLUDE"` to FILE must fail RULE.
breaks() {
    copy
    printf '#include "%s"\n' "$2" >> "$tmp/tree/$1"
    if out="$("$here/layering.sh" "$tmp/tree")"; then
        echo "not caught: $1 including $2"
        status=1
    elif ! grep -q "^$3" <<< "$out"; then
        echo "caught under another rule: $1 including $2: $out"
        status=1
    fi
}
breaks base/vec.h workloads/scene.h "base/ may include only base/"
breaks workloads/noise.cpp kernels/rng.h "workloads/ may include of the project only"
breaks kernels/trace.cpp workloads/scene.h "the trace library may include only"
breaks hw_model/op_costs.h kernels/bvh.h "hw_model/ may include of kernels/ only"
[ "$status" = 0 ] && echo "layering self-test: each rule fails when broken"
exit "$status"
