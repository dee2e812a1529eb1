#!/usr/bin/env bash
# The folder layering, as a test: the hardware model knows the tracers only through the trace
# types (kernels/trace.h), and the trace library is nearly a leaf (of the project it includes
# only the input-error and user-file helpers, to refuse a damaged trace file). Prints each
# offending include and fails.
set -euo pipefail
cd "$(dirname "$0")/../.."
bad=0
while IFS= read -r line; do
    echo "hw_model/ may include only kernels/trace.h of kernels/: $line"
    bad=1
done < <(grep -rn '#include "kernels/' hw_model/ | grep -v '#include "kernels/trace.h"' || true)
while IFS= read -r line; do
    echo "the trace library must be a leaf: $line"
    bad=1
done < <(grep -n '#include "' kernels/trace.h kernels/trace.cpp | grep -v '#include "kernels/trace.h"' |
                   grep -v '#include "base/input_error.h"' |
                   grep -v '#include "base/user_files.h"' || true)
if [ "$bad" = 0 ]; then echo "layering: hw_model/ sees kernels/ only through kernels/trace.h; trace library uses only the error and file helpers"; fi
exit "$bad"
