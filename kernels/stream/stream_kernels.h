#pragma once
// The stream filters' inner loops, one set per host instruction set (kernels/simd/isa.h),
// built from one width-generic source (stream_kernels_impl.h) in translation units compiled
// for that instruction set. Each processes Width lanes at a time: gather the ray fields of
// Width slots, test them against one node or primitive broadcast across the lanes, compress
// the passing slot ids. Every back end gives the same bits as the scalar one.

#include <cstddef>
#include <cstdint>

#include "kernels/intersect.h"
#include "kernels/simd/isa.h"

namespace sfx {

// What a box or triangle test gathers per lane, in one cache line: the test's constants and
// its t_max (the closest hit so far, or the ray's t_max; -1 for an occluded shadow ray, which
// every later box and primitive test then misses). Kernels gather its fields as 32-bit
// elements at 16 * slot + field.
struct alignas(64) TraversalRay {
    RayPrecomp pre;
    float t;
};
static_assert(sizeof(TraversalRay) == 64, "one cache line per ray");
namespace traversal_field {  // 32-bit element offsets inside TraversalRay
constexpr int org = int(offsetof(RayPrecomp, org) / 4);
constexpr int inv_dir = int(offsetof(RayPrecomp, inv_dir) / 4);
constexpr int kx = int(offsetof(RayPrecomp, kx) / 4);
constexpr int ky = int(offsetof(RayPrecomp, ky) / 4);
constexpr int kz = int(offsetof(RayPrecomp, kz) / 4);
constexpr int sx = int(offsetof(RayPrecomp, sx) / 4);
constexpr int sy = int(offsetof(RayPrecomp, sy) / 4);
constexpr int t = int(offsetof(TraversalRay, t) / 4);
}  // namespace traversal_field

// Room every id, position and scratch buffer needs past its length: a group's compress
// writes whole vectors.
constexpr uint32_t k_stream_padding = 16;

struct StreamKernels {
    Isa isa;
    uint32_t width;

    // Box filter (Fig. 5) of ids[0, n) against `box`: passing ids in order to pass_out, failing
    // ids in order to fail_out (pass_out may be ids itself: it never overtakes the reads, and
    // nothing past ids[n) is written).
    // Writes mask[i] (0/1, input order) when mask is not null. Adds to `negative` the passing
    // rays whose direction is negative on `axis` (the front-child vote). Returns the passing count.
    uint32_t (*box_filter)(const TraversalRay* rays, const Bounds3& box, int axis,
                           const uint32_t* ids, uint32_t n, uint32_t* pass_out, uint32_t* fail_out,
                           uint8_t* mask, uint32_t& negative);

    // The float stage of the watertight test of ids[0, n) against one triangle: writes the
    // positions i (in order) that it does not reject to `positions`; returns their count.
    uint32_t (*triangle_candidates)(const TraversalRay* rays, const Vec3& p0, const Vec3& p1,
                                    const Vec3& p2, const uint32_t* ids, uint32_t n,
                                    uint32_t* positions);

    // Stable partition of ids[0, n) by mask[i] != 0, passing first, by compress; returns the
    // passing count; writes nothing past ids[n). `scratch` holds n + k_stream_padding ids.
    uint32_t (*partition)(uint32_t* ids, uint32_t n, const uint8_t* mask, uint32_t* scratch);
};

// The kernels for a resolved instruction set (never Isa::automatic; the CPU must support it).
const StreamKernels& stream_kernels(Isa isa);

}  // namespace sfx
