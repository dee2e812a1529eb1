#!/usr/bin/env bash
# The folder layering, as a test. Prints each offending include and fails.
#   base/      includes nothing of the project but base/ (the ground layer)
#   workloads/ includes of the project only base/ and workloads/
#   the trace library (kernels/trace.h/.cpp) includes only base/ and itself (a leaf)
#   hw_model/  includes of kernels/ only the trace types (kernels/trace.h)
# Usage: layering.sh [ROOT] (default: this source tree; layering_selftest.sh passes a copy).
set -euo pipefail
root="${1:-$(dirname "$0")/../..}"
cd "$root"
bad=0
# project_includes FILES...: every `#include "folder/..."` line, as file:line:text.
project_includes() { grep -Hn '^[[:space:]]*#[[:space:]]*include[[:space:]]*"' "$@" || true; }
report() {  # report RULE: each input line breaks RULE
    while IFS= read -r line; do
        echo "$1: $line"
        bad=1
    done
}
report "base/ may include only base/" < <(
    project_includes $(find base -name '*.h' -o -name '*.cpp') | grep -v '#include "base/')
report "workloads/ may include of the project only base/ and workloads/" < <(
    project_includes $(find workloads -name '*.h' -o -name '*.cpp') |
        grep -v -E '#include "(base|workloads)/')
report "the trace library may include only base/ and kernels/trace.h" < <(
    project_includes kernels/trace.h kernels/trace.cpp | grep -v -E '#include "(base/|kernels/trace\.h")')
report "hw_model/ may include of kernels/ only kernels/trace.h" < <(
    project_includes $(find hw_model -name '*.h' -o -name '*.cpp') | grep '#include "kernels/' |
        grep -v '#include "kernels/trace.h"')
if [ "$bad" = 0 ]; then
    echo "layering: base/ is the ground; workloads/ and the trace library stand on it alone;" \
         "hw_model/ sees kernels/ only through kernels/trace.h"
fi
exit "$bad"
