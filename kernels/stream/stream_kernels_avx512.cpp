// The stream kernels at Width 16, compiled with the avx512 flags (kernels/CMakeLists.txt).
// Called only after kernels/simd/isa.h found the instruction set on the CPU.
#define SFX_KERNEL_ISA avx512_kernels
#include "kernels/stream/stream_kernels_impl.h"

namespace sfx {

const StreamKernels& stream_kernels_avx512() {
    static const StreamKernels kernels = avx512_kernels::make_kernels<16>(Isa::avx512);
    return kernels;
}

}  // namespace sfx
