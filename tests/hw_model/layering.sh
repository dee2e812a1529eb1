#!/usr/bin/env bash
# The folder layering, as a test: the hardware model knows the tracers only through the trace
# types (kernels/trace.h), and the trace library is a leaf (it includes nothing of the
# project). Prints each offending include and fails.
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
done < <(grep -n '#include "' kernels/trace.h kernels/trace.cpp | grep -v '#include "kernels/trace.h"' || true)
if [ "$bad" = 0 ]; then echo "layering: hw_model/ sees kernels/ only through kernels/trace.h; trace library a leaf"; fi
exit "$bad"
