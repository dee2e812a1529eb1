#pragma once
// The stream filters' inner loops, one set per host instruction set (kernels/simd/isa.h),
// built from one width-generic source (stream_kernels_impl.h) in translation units compiled
// for that instruction set. Each processes Width lanes at a time: gather the ray fields of
// Width slots, test them against one node or primitive broadcast across the lanes, compress
// the passing slot ids. Every back end gives the same bits as the scalar one.

#include <cstddef>
#include <cstdint>
#include <cstring>
#include <vector>

#include "kernels/intersect.h"
#include "kernels/simd/isa.h"

namespace sfx {

// The ray fields the box and triangle filters read, one array per field (structure of
// arrays): the test's constants and t (the closest hit so far, or the ray's t_max; -1 for an
// occluded shadow ray, which every later box and primitive test then misses). A group of
// Width slots reads each field by plain loads and permutes when its ids lie in one window of
// slots (kernels/simd/lanes.h, window_slots: 64 at 16 lanes, 16 at 8; stable partitions keep
// ids in runs), by a gather otherwise.
namespace traversal_field {  // the field arrays, in order
constexpr int org = 0, inv_dir = 3, t = 6, kx = 7, ky = 8, kz = 9, sx = 10, sy = 11, count = 12;
}  // namespace traversal_field

// Room past the last slot of each field array: a window read loads up to 64 elements.
constexpr uint32_t k_window_padding = 64;

// What the kernels read: field f of slot i at data[f * stride + i]. A plain view, so the wide
// translation units instantiate no out-of-line member of a library type.
struct TraversalView {
    const float* data;
    uint32_t stride;
};

class TraversalRays {
  public:
    // Room for `slots` rays; every field zero.
    void resize(uint32_t slots) {
        m_stride = slots + k_window_padding;
        m_data.assign(size_t(traversal_field::count) * m_stride, 0.f);
    }
    // Slot `slot` gets the test constants of `pre` and t.
    void set(uint32_t slot, const RayPrecomp& pre, float t) {
        namespace f = traversal_field;
        for (int a = 0; a < 3; ++a) {
            at(f::org + a, slot) = pre.org[a];
            at(f::inv_dir + a, slot) = pre.inv_dir[a];
        }
        at(f::t, slot) = t;
        const int32_t k[3] = {pre.kx, pre.ky, pre.kz};
        for (int a = 0; a < 3; ++a) std::memcpy(&at(f::kx + a, slot), &k[a], sizeof(float));
        at(f::sx, slot) = pre.sx;
        at(f::sy, slot) = pre.sy;
    }
    float& t(uint32_t slot) { return at(traversal_field::t, slot); }
    float t(uint32_t slot) const { return field(traversal_field::t)[slot]; }
    const float* field(int f) const { return m_data.data() + size_t(f) * m_stride; }
    TraversalView view() const { return {m_data.data(), m_stride}; }

  private:
    float& at(int f, uint32_t slot) { return m_data[size_t(f) * m_stride + slot]; }
    std::vector<float> m_data;
    uint32_t m_stride = 0;
};

// Room every id, position and scratch buffer needs past its length: a group's compress
// writes whole vectors.
constexpr uint32_t k_stream_padding = 16;

// Triangles a leaf_candidates call takes at most (the default leaf size).
constexpr uint32_t k_leaf_batch = 4;

struct StreamKernels {
    Isa isa;
    uint32_t width;

    // Box filter (Fig. 5) of ids[0, n) against `box`: passing ids in order to pass_out, failing
    // ids in order to fail_out (pass_out may be ids itself: it never overtakes the reads, and
    // nothing past ids[n) is written).
    // Writes mask[i] (0/1, input order) when mask is not null. Adds to `negative` the passing
    // rays whose direction is negative on `axis` (the front-child vote). Returns the passing count.
    uint32_t (*box_filter)(TraversalView rays, const Bounds3& box, int axis, const uint32_t* ids,
                           uint32_t n, uint32_t* pass_out, uint32_t* fail_out, uint8_t* mask,
                           uint32_t& negative);

    // The float stage of the watertight test of ids[0, n) against one triangle: writes the
    // positions i (in order) that it does not reject to `positions`; returns their count.
    uint32_t (*triangle_candidates)(TraversalView rays, const Vec3& p0, const Vec3& p1,
                                    const Vec3& p2, const uint32_t* ids, uint32_t n,
                                    uint32_t* positions);

    // triangle_candidates for up to k_leaf_batch triangles of a leaf at once (each group's ray
    // fields are read once for all of them): the positions triangle j does not reject go to
    // positions + j * stride, their count to found[j].
    void (*leaf_candidates)(TraversalView rays, const LeafPrimitive* triangles, uint32_t count,
                            const uint32_t* ids, uint32_t n, uint32_t* positions, uint32_t stride,
                            uint32_t* found);

    // Stable partition of ids[0, n) by mask[i] != 0, passing first, by compress; returns the
    // passing count; writes nothing past ids[n). `scratch` holds n + k_stream_padding ids.
    uint32_t (*partition)(uint32_t* ids, uint32_t n, const uint8_t* mask, uint32_t* scratch);
};

// The kernels for a resolved instruction set (never Isa::automatic; the CPU must support it).
const StreamKernels& stream_kernels(Isa isa);

}  // namespace sfx
