#pragma once
// The stream filters' inner loops, one set per host instruction set (kernels/simd/isa.h),
// built from one width-generic source (stream_kernels_impl.h) in translation units compiled
// for that instruction set. Each processes Width lanes at a time: read the ray fields of
// Width slots (one record half per slot, transposed into lanes), test them against one node or
// primitive broadcast across the lanes, compress the passing slot ids. Every back end gives the
// same bits as the scalar one.

#include <boost/align/aligned_allocator.hpp>
#include <cstddef>
#include <cstdint>
#include <cstring>
#include <vector>

#include "kernels/bvh.h"
#include "kernels/intersect.h"
#include "kernels/simd/isa.h"
#include "kernels/trace.h"

namespace sfx {

// The ray fields the box and triangle filters read, one 64-byte record (a cache line) per
// slot: the box test's half (inv_dir, t: the closest hit so far, or the ray's t_max; -1 for an
// occluded shadow ray, which every later box and primitive test then misses; org), then the
// triangle test's half (org again, kx, ky, kz, sx, sy). A group of Width slots scattered over
// the buffer touches one line per ray, not one per field; it reads a half by Width 32-byte
// loads and a transpose (kernels/simd/lanes.h, load_transposed). A stream whose rays share
// their origin (TraversalView::shared_origin) reads only the box half's first quarter.
namespace traversal_field {  // float offsets within a slot's record
constexpr int inv_dir = 0, t = 3, org = 4, box_half = 0;
constexpr int tri_org = 8, kx = 11, ky = 12, kz = 13, sx = 14, sy = 15, triangle_half = 8;
constexpr int record = 16;
}  // namespace traversal_field

// What the kernels read: field f of slot i at data[i * traversal_field::record + f], data
// 64-byte aligned. A plain view, so the wide translation units instantiate no out-of-line
// member of a library type.
struct TraversalView {
    const float* data;
    // Not null: every slot the kernel is given has this origin (x, y, z), so the box filter
    // reads only inv_dir and t.
    const float* shared_origin = nullptr;
};

// A primitive test's hit at t, taken if it is closer than the ray's hit so far (closer()): the
// hit record gets it (u, v = 0: a sphere's), the ray's t tightens to it, or to -1 for an
// any-hit ray (done). The sphere filter's step after the kernel, in the tracer and its
// microbenchmark.
SFX_LANES_INLINE bool take_closer_hit(float t, uint32_t prim, Hit& best, float& ray_t,
                                      bool any_hit) {
    if (!closer(t, prim, best)) return false;
    best.t = t;
    best.u = best.v = 0.f;
    best.prim = prim;
    ray_t = any_hit ? -1.f : t;
    return true;
}

class TraversalRays {
  public:
    // Room for `slots` rays; every field zero.
    void resize(uint32_t slots) { m_data.assign(size_t(slots) * traversal_field::record, 0.f); }
    // Slot `slot` gets the test constants of `pre` and t.
    void set(uint32_t slot, const RayPrecomp& pre, float t) {
        namespace f = traversal_field;
        float* r = record(slot);
        for (int a = 0; a < 3; ++a) {
            r[f::org + a] = pre.org[a];
            r[f::inv_dir + a] = pre.inv_dir[a];
            r[f::tri_org + a] = pre.org[a];
        }
        r[f::t] = t;  // the box half's last float stays the zero of resize()
        const int32_t k[3] = {pre.kx, pre.ky, pre.kz};
        std::memcpy(r + f::kx, k, sizeof k);
        r[f::sx] = pre.sx;
        r[f::sy] = pre.sy;
    }
    float& t(uint32_t slot) { return record(slot)[traversal_field::t]; }
    float t(uint32_t slot) const { return record(slot)[traversal_field::t]; }
    TraversalView view() const { return {m_data.data()}; }
    float* data() { return m_data.data(); }

  private:
    float* record(uint32_t slot) { return m_data.data() + size_t(slot) * traversal_field::record; }
    const float* record(uint32_t slot) const {
        return m_data.data() + size_t(slot) * traversal_field::record;
    }
    std::vector<float, boost::alignment::aligned_allocator<float, 64>> m_data;
};

// A ray set up for its generation's traversal (the tracer's load_rays, one ray): its any-hit
// flag (a shadow ray stops at any hit), no hit yet, the full tests' constants and the
// filters' fields. False for a ray that is not traced (ray_is_valid). The calibration's
// microbenchmarks time this with the op that made the ray (kernels/stream/stream_microbench.h).
inline bool set_up_ray(const Ray& r, bool shadow, uint32_t slot, uint8_t& any_hit, Hit& hit,
                       RayPrecomp& pre, TraversalRays& trav) {
    any_hit = shadow;
    hit = Hit{};
    if (!ray_is_valid(r)) return false;
    pre = RayPrecomp(r);
    trav.set(slot, pre, r.t_max);
    return true;
}

// Room every id, position and scratch buffer needs past its length: a group's compress
// writes whole vectors.
constexpr uint32_t k_stream_padding = 16;

// The size of TraversalJob::op_tally for streams of up to n rays: an op count, a pass count and
// a failed-candidate count per kind (box, triangle and sphere tests) and length (0 to n).
constexpr size_t op_tally_size(uint32_t n) {
    return 3 * 3 * (size_t(n) + 1);
}

// Triangles a leaf_candidates call takes at most (the default leaf size).
constexpr uint32_t k_leaf_batch = 4;

// How much of each op the traversal reports: nothing, counts (the op without its slots and
// pass flags: TraceSink::counts_only), or the whole op.
enum class TraceDetail : uint8_t { none, counts, lanes };
constexpr int k_trace_details = 3;

// One (node, stream length) of the traversal stack: the stream is the prefix of that length.
struct TraversalStackEntry {
    uint32_t node, length;
};
// A depth-first walk of a binary tree keeps at most one entry per level, plus the one popped.
constexpr uint32_t k_traversal_stack_size = Bvh::k_max_depth + 2;

// The one-ray loop's ([0]) and the few-ray loop's ([1]) entries from the stream loop, their
// TSC ticks with their leaves' (TraversalJob::leaf_tsc) left out, and their leaves' ticks.
struct ShortLoopClock {
    uint64_t ticks[2] = {0, 0};
    uint64_t entries[2] = {0, 0};
    uint64_t leaf_ticks[2] = {0, 0};
};

// What one traversal (Fig. 3) of a stream works on. Plain pointers, so the wide translation
// units instantiate no out-of-line member of a library type.
struct TraversalJob {
    const Bvh* bvh;  // its full triangle tests (intersect_leaf_triangle)
    const BvhNode* nodes;
    const LeafPrimitive* leaf;
    uint32_t triangle_count;  // leaf[i].prim >= triangle_count: a sphere (Scene::is_sphere)
    const Sphere* spheres;    // Scene::spheres: sphere prim is spheres[prim - triangle_count]
    float* rays;              // TraversalRays' records: t is tightened as hits are found
    const float* shared_origin;  // TraversalView::shared_origin of the stream (shared_origin())
    const RayPrecomp* pre;    // per slot: the full primitive tests' constants
    Hit* hit;                 // per slot: the closest hit so far
    const uint8_t* any_hit;   // per slot: a shadow ray, done at its first hit
    uint32_t* ids;            // the stream, n ids; every buffer has k_stream_padding of room
    uint32_t n;
    uint32_t entry;  // the node the stream enters at
    uint32_t *scratch, *scratch2;
    uint32_t* positions;  // k_leaf_batch * (n + k_stream_padding)
    uint8_t* mask;
    TraceSink* sink;  // null with TraceDetail::none
    // TraceDetail::counts: op_tally_size(n) zeros, where the traversal tallies its ops by kind
    // and length until it sends them (TraceSink::ops_of_length); zeros again after.
    uint32_t* op_tally;
    uint16_t generation;
    OpStage box_stage, triangle_stage, sphere_stage;  // stage_of(their kinds)
    uint64_t* leaf_tsc;                               // not null: adds the TSC ticks in leaves
    // Not null: counts the one-ray and few-ray loops entered from the stream loop and adds
    // their TSC ticks (ShortLoopClock).
    ShortLoopClock* short_loops;
};

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

    // The sphere test of ids[0, n) against `sphere` over (0, the slots' t]: mask[i] = hit
    // (0/1), and t[i] = its distance where it hits; pre holds the slots' directions. Both
    // buffers have k_stream_padding of room past n. Returns the hit count.
    uint32_t (*sphere_filter)(TraversalView rays, const RayPrecomp* pre, const Sphere& sphere,
                              const uint32_t* ids, uint32_t n, uint8_t* mask, float* t);

    // The traversal's leaf code (trace off) on the leaf primitives [first, first + count) for
    // job.ids[0, k): each primitive's test, its hits taken if closer (t tightened). Returns the
    // lanes that took a hit, summed over the primitives; one lane (k = 1) by the one-ray loop's
    // leaf code. The microbenchmarks time the triangle and sphere tests through it, so that
    // their costs are those of the code a frame runs.
    uint32_t (*leaf_tests)(const TraversalJob& job, uint32_t first, uint32_t count, uint32_t k);

    // Stable partition of ids[0, n) by mask[i] != 0, passing first, by compress; returns the
    // passing count; writes nothing past ids[n). `scratch` holds n + k_stream_padding ids.
    uint32_t (*partition)(uint32_t* ids, uint32_t n, const uint8_t* mask, uint32_t* scratch);

    // The whole traversal of Fig. 3 for job.ids[0, n) (stream_tracer.cpp says what it does),
    // calling the box filter and the leaves' float stage directly, not through this table;
    // indexed by TraceDetail.
    void (*traverse[k_trace_details])(const TraversalJob& job);
};

// The origin (x, y, z in the first slot's record) that every slot of ids[0, n) has, bit for
// bit (a pinhole camera's primary stream), or null.
const float* shared_origin(const float* rays, const uint32_t* ids, uint32_t n);

// The kernels for a resolved instruction set (never Isa::automatic; the CPU must support it).
const StreamKernels& stream_kernels(Isa isa);

// A job's fields that come from the BVH (nodes, leaf primitives, the triangle count, the
// stages of the test kinds), entering at the root; the caller sets the buffers, the stream and
// the trace.
TraversalJob traversal_job(const Bvh& bvh);

// traversal_job with the per-slot fields and scratch lists of `b` (the tracer's and the
// microbenchmarks' buffers name them alike); the caller sets the stream and the trace.
template <class Buffers>
TraversalJob traversal_job(const Bvh& bvh, Buffers& b) {
    TraversalJob job = traversal_job(bvh);
    job.rays = b.trav.data();
    job.pre = b.pre.data();
    job.hit = b.hit.data();
    job.any_hit = b.any_hit.data();
    job.scratch = b.scratch.data();
    job.scratch2 = b.scratch2.data();
    job.positions = b.positions.data();
    job.mask = b.mask.data();
    job.op_tally = b.op_tally.data();
    return job;
}

}  // namespace sfx
