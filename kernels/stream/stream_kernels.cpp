// The scalar stream kernels (Width 1, the default flags) and the choice among back ends.
#define SFX_KERNEL_ISA scalar_kernels
#include "kernels/stream/stream_kernels_impl.h"

namespace sfx {

const StreamKernels& stream_kernels_avx2();    // stream_kernels_avx2.cpp
const StreamKernels& stream_kernels_avx512();  // stream_kernels_avx512.cpp

const StreamKernels& stream_kernels(Isa isa) {
    static const StreamKernels scalar = scalar_kernels::make_kernels<1>(Isa::scalar);
    switch (isa) {
        case Isa::avx512:
            return stream_kernels_avx512();
        case Isa::avx2:
            return stream_kernels_avx2();
        default:
            return scalar;
    }
}

}  // namespace sfx
