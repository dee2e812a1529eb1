// The stream kernels at Width 8, compiled with the avx2 flags (kernels/CMakeLists.txt).
// Called only after kernels/simd/isa.h found the instruction set on the CPU.
#define SFX_KERNEL_ISA avx2_kernels
#include "kernels/stream/stream_kernels_impl.h"

namespace sfx {

const StreamKernels& stream_kernels_avx2() {
    static const StreamKernels kernels = avx2_kernels::make_kernels<8>(Isa::avx2);
    return kernels;
}

}  // namespace sfx
