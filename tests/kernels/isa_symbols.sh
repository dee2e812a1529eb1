#!/usr/bin/env bash
# The AVX2 and AVX-512 stream-kernel objects define code only inside their own namespaces
# (sfx::avx2_kernels, sfx::avx512_kernels) and their one entry point. Anything else (an inline
# function of a shared header emitted out of line) could be picked by the linker for every
# caller, and a machine without that instruction set would crash with SIGILL.
# Usage: isa_symbols.sh LIBRARY.a
set -euo pipefail
lib=$1
bad=0
for isa in avx2 avx512; do
  object=stream_kernels_${isa}.cpp.o
  syms=$(nm -C --defined-only "$lib" 2>/dev/null | awk -v o="$lib[$object]:" -v f="$object:" '
    /:$/ { on = ($0 == f || $0 == o); next } on && $2 ~ /^[TWVtw]$/ { $1 = ""; $2 = ""; print }')
  [[ -n "$syms" ]] || { echo "no symbols found for $object in $lib"; exit 1; }
  # _sub_I_/_sub_D_: a sanitizer's per-object constructor and destructor (local, never shared).
  # DW.ref.__gxx_personality_v0: a data word holding the C++ unwinder's address, which an
  # object with unwind tables refers to (ASan builds give the kernels some); not code.
  stray=$(grep -v -e "sfx::${isa}_kernels::" -e "sfx::stream_kernels_${isa}()" \
    -e "^ *_sub_[ID]_[0-9]*_[0-9]*$" -e "^ *DW\.ref\.__gxx_personality_v0$" <<<"$syms" || true)
  if [[ -n "$stray" ]]; then
    echo "$object defines code outside sfx::${isa}_kernels:"; echo "$stray"; bad=1
  fi
done
exit $bad
