// The scalar stream kernels (Width 1, the default flags) and the choice among back ends.
#define SFX_KERNEL_ISA scalar_kernels
#include "kernels/stream/stream_kernels_impl.h"

namespace sfx {

const StreamKernels& stream_kernels_avx2();    // stream_kernels_avx2.cpp
const StreamKernels& stream_kernels_avx512();  // stream_kernels_avx512.cpp

TraversalJob traversal_job(const Bvh& bvh) {
    TraversalJob job{};
    job.bvh = &bvh;
    job.nodes = bvh.nodes().data();
    job.leaf = bvh.leaf_primitives().data();
    job.triangle_count = uint32_t(bvh.scene().triangles.size());
    job.spheres = bvh.scene().spheres.data();
    job.entry = 0;
    job.box_stage = stage_of(OpKind::box_test);
    job.triangle_stage = stage_of(OpKind::triangle_test);
    job.sphere_stage = stage_of(OpKind::sphere_test);
    return job;
}

const float* shared_origin(const float* rays, const uint32_t* ids, uint32_t n) {
    namespace f = traversal_field;
    if (n == 0) return nullptr;
    const float* first = rays + size_t(ids[0]) * f::record + f::org;
    for (uint32_t i = 1; i < n; ++i)
        if (std::memcmp(rays + size_t(ids[i]) * f::record + f::org, first, 3 * sizeof(float)))
            return nullptr;
    return first;
}

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
