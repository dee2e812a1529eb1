#pragma once
// The width-generic source of the stream kernels (stream_kernels.h). Included by exactly one
// translation unit per instruction set, which defines SFX_KERNEL_ISA (the namespace its
// instantiations live in) and is compiled with that instruction set's flags: stream_kernels.cpp
// (scalar, Width 1), stream_kernels_avx2.cpp (Width 8), stream_kernels_avx512.cpp (Width 16).
// Only always-inline lane operations and the shared ray math of intersect.h are used here,
// so no out-of-line function compiled with wide instructions escapes its namespace.

#include <x86intrin.h>

#include <cstring>
#include <type_traits>

#include "kernels/intersect.h"
#include "kernels/simd/lanes.h"
#include "kernels/stream/stream_kernels.h"

#ifndef SFX_KERNEL_ISA
#error "define SFX_KERNEL_ISA before including stream_kernels_impl.h"
#endif

namespace sfx {
namespace SFX_KERNEL_ISA {

// The active lanes of the group that starts `left` ids before the end of the stream.
template <int Width>
SFX_LANES_INLINE uint32_t active_bits(uint32_t left) {
    return left >= uint32_t(Width) ? (1u << Width) - 1u : (1u << left) - 1u;
}

// ids[g, g + Width) with the inactive lanes of a partial group set to ids[g] (a slot that
// exists, so their gathers stay inside the ray buffer; their results are masked off).
template <int Width>
SFX_LANES_INLINE vint<Width> load_ids(const uint32_t* ids, uint32_t active) {
    const vint<Width> id = load_int<Width>(ids);
    return select(from_bits<Width>(active), id, broadcast_int<Width>(int32_t(ids[0])));
}

// Compress-store at out that never writes past out[count) in a partial group: an in-place
// partition's ids past the stream belong to the streams around it.
template <int Width>
SFX_LANES_INLINE uint32_t compress_append(uint32_t mask_bits, vint<Width> values, uint32_t* out,
                                          bool full_group) {
    return full_group ? compress_store<Width>(mask_bits, values, out)
                      : compress_store_exact<Width>(mask_bits, values, out);
}

// Copies n ids between two buffers inline: a filter's failing ids, most often a few (a library
// memcpy call per op costs more than the copy). Never writes past out[n): ids past a stream
// belong to the streams around it.
SFX_LANES_INLINE void copy_ids(uint32_t* out, const uint32_t* in, uint32_t n) {
    if (n >= 8) {
        for (uint32_t i = 0; i + 8 <= n; i += 8) __builtin_memcpy(out + i, in + i, 32);
        __builtin_memcpy(out + n - 8, in + n - 8, 32);  // the tail, overlapping
    } else if (n >= 4) {
        __builtin_memcpy(out, in, 16);
        __builtin_memcpy(out + n - 4, in + n - 4, 16);
    } else if (n >= 2) {
        __builtin_memcpy(out, in, 8);
        __builtin_memcpy(out + n - 2, in + n - 2, 8);
    } else if (n == 1) {
        out[0] = in[0];
    }
}

// Calls group(std::integral_constant<int, W>(), g) for each group of Width ids from g = 0 while
// g < n. A last group of at most half the width (a short stream, or a stream's tail) runs at
// half the width (16 -> 8, 8 -> 4): half the reads and lane work on short secondary streams;
// the lane math is the same at every width, so are the results.
template <int Width, class Group>
SFX_LANES_INLINE void for_each_group(uint32_t n, Group&& group) {
    for (uint32_t g = 0; g < n; g += Width) {
        if constexpr (Width == 16 || Width == 8) {
            if (n - g <= Width / 2) return group(std::integral_constant<int, Width / 2>(), g);
        }
        group(std::integral_constant<int, Width>(), g);
    }
}

// The ray fields of one group, as lanes: the box test's and the triangle test's.
template <int Width>
struct BoxLanes {
    vfloat<Width> org[3], inv_dir[3], t;
};
template <int Width>
struct TriangleLanes {
    vfloat<Width> org[3];
    vint<Width> kx, ky, kz;
    vfloat<Width> sx, sy;
};

// One group's slot ids and its reads of their records' halves (stream_kernels.h).
template <int Width>
struct GroupReader {
    const float* data;
    vint<Width> id;
    alignas(64) int32_t offset[Width];  // each lane's record, in floats from data

    SFX_LANES_INLINE GroupReader(TraversalView rays, const uint32_t* ids, uint32_t active)
        : data(rays.data), id(load_ids<Width>(ids, active)) {
        if (active == (1u << Width) - 1u) {
            for (int l = 0; l < Width; ++l) offset[l] = int32_t(ids[l]) * traversal_field::record;
        } else {
            const vint<Width> o = id * broadcast_int<Width>(traversal_field::record);
            __builtin_memcpy(offset, &o, sizeof offset);
        }
    }
    // The box test's half of every lane's record.
    SFX_LANES_INLINE BoxLanes<Width> read_box() const {
        namespace f = traversal_field;
        vfloat<Width> h[8];
        load_transposed<Width>(data + f::box_half, offset, h);
        return {{h[f::org], h[f::org + 1], h[f::org + 2]},
                {h[f::inv_dir], h[f::inv_dir + 1], h[f::inv_dir + 2]},
                h[f::t]};
    }
    // The box half's first quarter (inv_dir and t), for lanes that share their origin.
    SFX_LANES_INLINE BoxLanes<Width> read_box_directions() const {
        namespace f = traversal_field;
        static_assert(f::inv_dir == 0 && f::t == 3, "inv_dir and t lead the box half");
        vfloat<Width> h[4];
        load_transposed<Width, 4>(data + f::box_half, offset, h);
        return {{}, {h[f::inv_dir], h[f::inv_dir + 1], h[f::inv_dir + 2]}, h[f::t]};
    }
    // The triangle test's half of every lane's record.
    SFX_LANES_INLINE TriangleLanes<Width> read_triangle() const {
        namespace f = traversal_field;
        vfloat<Width> h[8];
        load_transposed<Width>(data + f::triangle_half, offset, h);
        const int o = f::triangle_half;
        return {{h[f::tri_org - o], h[f::tri_org + 1 - o], h[f::tri_org + 2 - o]},
                as_int(h[f::kx - o]),
                as_int(h[f::ky - o]),
                as_int(h[f::kz - o]),
                h[f::sx - o],
                h[f::sy - o]};
    }

  private:
    // The lanes' bits as integers (kx, ky, kz are stored in float records).
    static SFX_LANES_INLINE vint<Width> as_int(vfloat<Width> v) {
        vint<Width> r;
        __builtin_memcpy(&r, &v, sizeof r);
        return r;
    }
};

// How many of the `lanes` point down the split axis, for the front-child vote: dir < 0 is
// inv_dir < 0, except inv_dir = -inf (dir = -0; RayPrecomp flushes denormals, so a negative
// normal dir has a finite inverse).
template <int Width>
SFX_LANES_INLINE uint32_t negative_lanes(const vfloat<Width> (&inv_dir)[3], int axis,
                                         uint32_t lanes) {
    if constexpr (Width == 1) {
        // Indexed and without jumps (GCC's code for the ternaries and &&): the one-ray loop
        // votes at every inner node, whose split axis changes from node to node and whose
        // sign follows the ray's direction: jumps mispredict on a frame's bounced rays, not on
        // the microbenchmarks' rays of fixed y and z signs (slab_entry_exit, kernels/intersect.h).
        const float inv = inv_dir[axis];
        return uint32_t((inv < 0.f) & (inv != -INFINITY)) & lanes;
    } else {
        const vfloat<Width> inv = axis == 0 ? inv_dir[0] : axis == 1 ? inv_dir[1] : inv_dir[2];
        const vfloat<Width> zero = broadcast<Width>(0.f), minus_inf = broadcast<Width>(-INFINITY);
        return uint32_t(__builtin_popcount(
            bits<Width>(mask_and<vbool<Width>>(inv < zero, inv != minus_inf)) & lanes));
    }
}

// A node's children in push order: `back` (popped last), then `front`, the right child in
// front where right_first. By an xor swap, not a jump: the choice follows the rays' direction
// signs (negative_lanes), and GCC's jumps for it mispredict on a frame's bounced rays.
struct ChildOrder {
    uint32_t back, front;
};
SFX_LANES_INLINE ChildOrder child_order(uint32_t node_index, const BvhNode& node,
                                        bool right_first) {
    const uint32_t left = BvhNode::left(node_index), right = node.right();
    const uint32_t swap = (left ^ right) & (0u - uint32_t(right_first));
    return {right ^ swap, left ^ swap};
}

// One group of box_filter: the `left` ids from ids on (all of them if left >= Width).
// Shared: the lanes share their origin, and `box` is relative to it.
template <int Width, bool Shared>
SFX_LANES_INLINE void box_group(TraversalView rays, const Bounds3& box, int axis,
                                const uint32_t* ids, uint32_t left, uint32_t* pass_out,
                                uint32_t* fail_out, uint8_t* mask, uint32_t& front, uint32_t& back,
                                uint32_t& negatives) {
    const uint32_t active = active_bits<Width>(left);
    const GroupReader<Width> r(rays, ids, active);
    vfloat<Width> t0;
    uint32_t pass;
    BoxLanes<Width> ray;
    if constexpr (Shared) {
        ray = r.read_box_directions();
        pass = bits<Width>(slab_test<Width>(BoxRelativeToOrigin(), ray.inv_dir, ray.t, box, t0)) &
               active;
    } else {
        ray = r.read_box();
        pass = bits<Width>(slab_test<Width>(ray.org, ray.inv_dir, ray.t, box, t0)) & active;
    }
    negatives += negative_lanes<Width>(ray.inv_dir, axis, pass);
    if (mask) store_mask_bytes<Width>(pass, mask);
    const bool full = left >= uint32_t(Width);
    front += compress_append<Width>(pass, r.id, pass_out + front, full);
    back += compress_append<Width>(~pass & active, r.id, fail_out + back, full);
}

template <int Width>
uint32_t box_filter(TraversalView rays, const Bounds3& box, int axis, const uint32_t* ids,
                    uint32_t n, uint32_t* pass_out, uint32_t* fail_out, uint8_t* mask,
                    uint32_t& negative) {
    uint32_t front = 0, back = 0, negatives = 0;
    // Forced: GCC otherwise keeps the 8-lane group out of line (primary rays +10 % on AVX2).
    auto groups = [&](auto shared, const Bounds3& b) __attribute__((always_inline)) {
        for_each_group<Width>(
            n, [&](auto width, uint32_t g) __attribute__((always_inline)) {
                box_group<decltype(width)::value, decltype(shared)::value>(
                    rays, b, axis, ids + g, n - g, pass_out, fail_out, mask ? mask + g : nullptr,
                    front, back, negatives);
            });
    };
    if (rays.shared_origin) {
        Bounds3 relative;  // the planes less the shared origin: once per box, not per lane
        for (int a = 0; a < 3; ++a) {
            relative.lo[a] = box.lo[a] - rays.shared_origin[a];
            relative.hi[a] = box.hi[a] - rays.shared_origin[a];
        }
        groups(std::true_type(), relative);
    } else {
        groups(std::false_type(), box);
    }
    negative += negatives;
    return front;
}

template <int Width>
uint32_t triangle_candidates(TraversalView rays, const Vec3& p0, const Vec3& p1, const Vec3& p2,
                             const uint32_t* ids, uint32_t n, uint32_t* positions) {
    uint32_t k = 0;
    for (uint32_t g = 0; g < n; g += Width) {
        const uint32_t active = active_bits<Width>(n - g);
        const GroupReader<Width> r(rays, ids + g, active);
        const TriangleLanes<Width> ray = r.read_triangle();
        const ShearedTriangle<Width> s =
            shear_triangle<Width>(ray.org, ray.kx, ray.ky, ray.kz, ray.sx, ray.sy, p0, p1, p2);
        const uint32_t keep = ~bits<Width>(edges_reject<Width>(s)) & active;
        k += compress_store<Width>(keep, lane_index<Width>() + broadcast_int<Width>(int32_t(g)),
                                   positions + k);  // positions has room past n
    }
    return k;
}

// One group of leaf_candidates: the `left` ids from ids + g on.
template <int Width>
SFX_LANES_INLINE void leaf_group(TraversalView rays, const LeafPrimitive* triangles, uint32_t count,
                                 const uint32_t* ids, uint32_t g, uint32_t left,
                                 uint32_t* positions, uint32_t stride, uint32_t* found) {
    const uint32_t active = active_bits<Width>(left);
    const GroupReader<Width> r(rays, ids + g, active);
    const TriangleLanes<Width> ray = r.read_triangle();
    const vint<Width> position = lane_index<Width>() + broadcast_int<Width>(int32_t(g));
    for (uint32_t j = 0; j < count; ++j) {
        const LeafPrimitive& tri = triangles[j];
        const ShearedTriangle<Width> s = shear_triangle<Width>(
            ray.org, ray.kx, ray.ky, ray.kz, ray.sx, ray.sy, tri.p0, tri.p1, tri.p2);
        const uint32_t keep = ~bits<Width>(edges_reject<Width>(s)) & active;
        found[j] += compress_store<Width>(keep, position,
                                          positions + j * stride + found[j]);  // room past n
    }
}

template <int Width>
void leaf_candidates(TraversalView rays, const LeafPrimitive* triangles, uint32_t count,
                     const uint32_t* ids, uint32_t n, uint32_t* positions, uint32_t stride,
                     uint32_t* found) {
    for (uint32_t j = 0; j < count; ++j) found[j] = 0;
    if (n == 1)  // one ray (most leaf ops of secondary rays): no wide group's reads and transposes
        return leaf_group<1>(rays, triangles, count, ids, 0, 1, positions, stride, found);
    for_each_group<Width>(n, [&](auto width, uint32_t g) {
        leaf_group<decltype(width)::value>(rays, triangles, count, ids, g, n - g, positions, stride,
                                           found);
    });
}

// One group of partition: the `left` ids from ids + g on.
template <int Width>
SFX_LANES_INLINE void partition_group(uint32_t* ids, uint32_t g, uint32_t left,
                                      const uint8_t* mask, uint32_t* scratch, uint32_t& front,
                                      uint32_t& back) {
    const uint32_t active = active_bits<Width>(left);
    const vint<Width> id = load_int<Width>(ids + g);
    const uint32_t pass = load_mask_bytes<Width>(mask + g) & active;
    const bool full = left >= uint32_t(Width);  // front <= g: ids[front, g + Width) are read
    front += compress_append<Width>(pass, id, ids + front, full);
    back += compress_append<Width>(~pass & active, id, scratch + back, full);
}

template <int Width>
uint32_t partition(uint32_t* ids, uint32_t n, const uint8_t* mask, uint32_t* scratch) {
    uint32_t front = 0, back = 0;
    for_each_group<Width>(n, [&](auto width, uint32_t g) {
        partition_group<decltype(width)::value>(ids, g, n - g, mask, scratch, front, back);
    });
    // Always: the whole-vector stores overwrote ids[0, n) past the passing prefix.
    copy_ids(ids + front, scratch, back);
    return front;
}

// Whether an op is the traversal's first: the box test of its entry node, which no other op of
// the traversal tests (StreamOp::starts_traversal).
SFX_LANES_INLINE bool starts_traversal(const TraversalJob& job, OpKind kind, uint32_t object) {
    return kind == OpKind::box_test && object == job.entry;
}

// Reports one op of the traversal to job.sink at the detail asked for.
template <TraceDetail Detail>
SFX_LANES_INLINE void report(const TraversalJob& job, OpKind kind, OpStage stage, uint32_t object,
                             const uint32_t* ids, uint32_t n, const uint8_t* mask, uint32_t passed,
                             uint32_t failed_candidates) {
    if constexpr (Detail != TraceDetail::none) {
        if constexpr (Detail != TraceDetail::lanes) ids = nullptr, mask = nullptr;
        const bool starts = starts_traversal(job, kind, object);
        job.sink->op(StreamOp{kind, stage, job.generation, object, n, passed, ids, mask,
                              failed_candidates, starts, starts && job.shared_origin});
    }
}

// Reports each op to job.sink at the detail asked for.
template <TraceDetail Detail>
struct SinkReporter {
    const TraversalJob& job;
    SFX_LANES_INLINE void operator()(OpKind kind, OpStage stage, uint32_t object,
                                     const uint32_t* ids, uint32_t n, const uint8_t* mask,
                                     uint32_t passed, uint32_t failed_candidates) const {
        report<Detail>(job, kind, stage, object, ids, n, mask, passed, failed_candidates);
    }
};

// Tallies a traversal's ops by kind and length for a sink that reads counts only
// (TraceDetail::counts) and sends them at the traversal's end (TraceSink::ops_of_length): one
// call per kind and length instead of one per op (a path-traced frame has hundreds of thousands
// of ops, and few lengths). The first op goes to the sink at once: a counting sink counts a
// generation's rays from its first box test's lanes, the one count that depends on order.
struct OpTally {
    const TraversalJob& job;
    bool first = true;
    uint32_t longest[3] = {0, 0, 0};  // per kind: the longest op tallied

    // job.op_tally: op counts [kind][length], then pass counts [kind][length], then failed
    // candidates [kind][length].
    SFX_LANES_INLINE uint32_t* ops(int k) const { return job.op_tally + size_t(k) * (job.n + 1); }
    SFX_LANES_INLINE uint32_t* passes(int k) const { return ops(k) + 3 * (size_t(job.n) + 1); }
    SFX_LANES_INLINE uint32_t* failed(int k) const { return ops(k) + 6 * (size_t(job.n) + 1); }

    SFX_LANES_INLINE void operator()(OpKind kind, OpStage stage, uint32_t object, const uint32_t*,
                                     uint32_t n, const uint8_t*, uint32_t pass,
                                     uint32_t failed_candidates) {
        if (first) {
            first = false;
            const bool starts = starts_traversal(job, kind, object);
            job.sink->op(StreamOp{kind, stage, job.generation, object, n, pass, nullptr, nullptr,
                                  failed_candidates, starts, starts && job.shared_origin});
            return;
        }
        const int k = kind == OpKind::box_test ? 0 : kind == OpKind::triangle_test ? 1 : 2;
        ++ops(k)[n];
        passes(k)[n] += pass;
        failed(k)[n] += failed_candidates;
        longest[k] = n > longest[k] ? n : longest[k];
    }
    // Sends the tallies and zeros them.
    SFX_LANES_INLINE void send() const {
        const OpKind kinds[3] = {OpKind::box_test, OpKind::triangle_test, OpKind::sphere_test};
        const OpStage stages[3] = {job.box_stage, job.triangle_stage, job.sphere_stage};
        for (int k = 0; k < 3; ++k) {
            uint32_t *count = ops(k), *passed = passes(k), *failed_candidates = failed(k);
            for (uint32_t n = 1; n <= longest[k]; ++n) {
                if (count[n] == 0) continue;
                job.sink->ops_of_length(kinds[k], stages[k], job.generation, n, count[n], passed[n],
                                        failed_candidates[n]);
                count[n] = passed[n] = failed_candidates[n] = 0;
            }
        }
    }
};

// The full test of the triangle at leaf position i (its triangle_normal given) for slot id.
// Closest hit: later tests need t or less. Any hit: the ray is done, and with t = -1 every
// later box and primitive test misses it.
SFX_LANES_INLINE bool full_triangle_test(const TraversalJob& job, uint32_t i,
                                         const TriangleNormal& normal, uint32_t id) {
    float& t = job.rays[size_t(id) * traversal_field::record + traversal_field::t];
    if (!job.bvh->intersect_leaf_triangle(job.pre[id], i, normal, t, job.hit[id])) return false;
    t = job.any_hit[id] ? -1.f : job.hit[id].t;
    return true;
}

// The sphere test of one group: the `left` ids from ids on (all of them if left >= Width) at
// Width. Returns the lanes that hit; lane_t[l] is lane l's t where it hits.
template <int Width>
SFX_LANES_INLINE uint32_t sphere_lanes(TraversalView rays, const RayPrecomp* pre,
                                       const Sphere& sphere, const uint32_t* ids, uint32_t left,
                                       float* lane_t) {
    const uint32_t active = active_bits<Width>(left);
    const GroupReader<Width> r(rays, ids, active);
    const BoxLanes<Width> ray = r.read_box();  // org and t; the direction is RayPrecomp's
    alignas(64) float d[3][Width];
    for (int l = 0; l < Width; ++l) {
        const Vec3& dir = pre[ids[uint32_t(l) < left ? l : 0]].dir;
        d[0][l] = dir.x, d[1][l] = dir.y, d[2][l] = dir.z;
    }
    vfloat<Width> dir[3];
    for (int a = 0; a < 3; ++a) __builtin_memcpy(&dir[a], d[a], sizeof dir[a]);
    vfloat<Width> t{};  // no lane hits: sphere_test may return before setting it
    const uint32_t hits = bits<Width>(sphere_test<Width>(ray.org, dir, ray.t, sphere, t)) & active;
    __builtin_memcpy(lane_t, &t, sizeof t);
    return hits;
}

template <int Width>
uint32_t sphere_filter(TraversalView rays, const RayPrecomp* pre, const Sphere& sphere,
                       const uint32_t* ids, uint32_t n, uint8_t* mask, float* t) {
    uint32_t passed = 0;
    for_each_group<Width>(n, [&](auto width, uint32_t g) {
        constexpr int W = decltype(width)::value;
        alignas(64) float lane_t[W];
        const uint32_t hits = sphere_lanes<W>(rays, pre, sphere, ids + g, n - g, lane_t);
        store_mask_bytes<W>(hits, mask + g);
        for (uint32_t h = hits; h != 0; h &= h - 1)
            t[g + __builtin_ctz(h)] = lane_t[__builtin_ctz(h)];
        passed += uint32_t(__builtin_popcount(hits));
    });
    return passed;
}

// A leaf's sphere `prim` against job.ids[0, k) by sphere_lanes: a lane that hits closer than
// its ray's hit so far takes the hit (take_closer_hit), as full_triangle_test does. Under
// TraceDetail::lanes, job.mask[0, k) gets the lanes that took it. Returns their count.
template <int Width, TraceDetail Detail>
SFX_LANES_INLINE uint32_t sphere_leaf(const TraversalJob& job, uint32_t prim, uint32_t k) {
    namespace f = traversal_field;
    const Sphere& sphere = job.spheres[prim - job.triangle_count];
    uint32_t passed = 0;
    for_each_group<Width>(k, [&](auto width, uint32_t g) {
        constexpr int W = decltype(width)::value;
        const uint32_t* ids = job.ids + g;
        alignas(64) float lane_t[W];
        uint32_t took = 0;
        for (uint32_t h =
                 sphere_lanes<W>(TraversalView{job.rays}, job.pre, sphere, ids, k - g, lane_t);
             h != 0; h &= h - 1) {
            const int l = __builtin_ctz(h);
            const uint32_t id = ids[l];
            if (take_closer_hit(lane_t[l], prim, job.hit[id],
                                job.rays[size_t(id) * f::record + f::t], job.any_hit[id]))
                took |= 1u << l;
        }
        if constexpr (Detail == TraceDetail::lanes) store_mask_bytes<W>(took, job.mask + g);
        passed += uint32_t(__builtin_popcount(took));
    });
    return passed;
}

// The primitives of a leaf against its stream ids[0, k): spheres by sphere_leaf at Width;
// runs of up to k_leaf_batch triangles by the float stage of the watertight test at
// Width (each group's rays read once for all of them; it does not depend on t), which rejects
// most lanes, then the full tests on the candidates it leaves, triangle by triangle in order.
template <int Width, TraceDetail Detail, class Report>
SFX_LANES_INLINE void traverse_leaf(const TraversalJob& job, const BvhNode& node, uint32_t k,
                                    Report& report_op) {
    const LeafPrimitive* leaf = job.leaf;
    uint32_t* ids = job.ids;
    uint8_t* mask = job.mask;
    const TraversalView view{job.rays};
    const uint32_t end = node.first + node.count;
    for (uint32_t i = node.first; i < end;) {
        if (leaf[i].prim >= job.triangle_count) {
            const uint32_t passed = sphere_leaf<Width, Detail>(job, leaf[i].prim, k);
            report_op(OpKind::sphere_test, job.sphere_stage, leaf[i].prim, ids, k, mask, passed, 0);
            ++i;
            continue;
        }
        uint32_t batch = 1;
        while (batch < k_leaf_batch && i + batch < end && leaf[i + batch].prim < job.triangle_count)
            ++batch;
        uint32_t found[k_leaf_batch];
        const uint32_t stride = k + k_stream_padding;
        leaf_candidates<Width>(view, &leaf[i], batch, ids, k, job.positions, stride, found);
        for (uint32_t j = 0; j < batch; ++j, ++i) {
            const uint32_t* candidates = job.positions + j * stride;
            if constexpr (Detail == TraceDetail::lanes) __builtin_memset(mask, 0, k);
            uint32_t passed = 0;
            // Once for the op's candidates (the full test's plane, in double).
            const TriangleNormal normal = found[j] != 0
                                              ? triangle_normal(leaf[i].p0, leaf[i].p1, leaf[i].p2)
                                              : TriangleNormal{};
            for (uint32_t c = 0; c < found[j]; ++c) {
                const uint32_t at = candidates[c];
                if (!full_triangle_test(job, i, normal, ids[at])) continue;
                ++passed;
                if constexpr (Detail == TraceDetail::lanes) mask[at] = 1;
            }
            report_op(OpKind::triangle_test, job.triangle_stage, leaf[i].prim, ids, k, mask, passed,
                      found[j] - passed);
        }
    }
}

// traverse_leaf (trace off) on the leaf primitives [first, first + count) for job.ids[0, k):
// the microbenchmarks time the leaf tests through the tracer's own leaf code, a one-lane
// stream's in the one-ray loop's (Width 1, as traverse_one calls it; the machine model prices
// a one-lane op by its one_lane_cycles). Returns the lanes that took a hit, summed over the
// primitives.
template <int Width>
uint32_t leaf_tests(const TraversalJob& job, uint32_t first, uint32_t count, uint32_t k) {
    BvhNode leaf;
    leaf.first = first;
    leaf.count = uint16_t(count);
    uint32_t passed = 0;
    auto add_passed = [&](OpKind, OpStage, uint32_t, const uint32_t*, uint32_t, const uint8_t*,
                          uint32_t op_passed, uint32_t) { passed += op_passed; };
    if (k == 1)
        traverse_leaf<1, TraceDetail::none>(job, leaf, 1, add_passed);
    else
        traverse_leaf<Width, TraceDetail::none>(job, leaf, k, add_passed);
    return passed;
}

// traverse_leaf, its TSC ticks added to job.leaf_tsc when the caller asks for the stage clock.
template <int Width, TraceDetail Detail, class Report>
SFX_LANES_INLINE void timed_leaf(const TraversalJob& job, const BvhNode& node, uint32_t k,
                                 Report& report_op) {
    const uint64_t start = job.leaf_tsc ? __rdtsc() : 0;
    traverse_leaf<Width, Detail>(job, node, k, report_op);
    if (job.leaf_tsc) *job.leaf_tsc += __rdtsc() - start;
}

// `loop` (the one-ray loop 0, the few-ray loop 1), counted and its TSC ticks less its leaves',
// and its leaves', added to job.short_loops when the caller asks for them.
template <class Loop>
SFX_LANES_INLINE void timed_short_loop(const TraversalJob& job, int loop, Loop&& run) {
    if (!job.short_loops) return run();
    const uint64_t leaf = job.leaf_tsc ? *job.leaf_tsc : 0, start = __rdtsc();
    run();
    const uint64_t in_leaves = job.leaf_tsc ? *job.leaf_tsc - leaf : 0;
    job.short_loops->ticks[loop] += __rdtsc() - start - in_leaves;
    job.short_loops->leaf_ticks[loop] += in_leaves;
    ++job.short_loops->entries[loop];
}

// What a node's test will need next arrives while the test runs: an interior node's
// children, a leaf's primitives (four by default: 160 bytes).
SFX_LANES_INLINE void prefetch_below(const TraversalJob& job, uint32_t node_index,
                                     const BvhNode& node) {
    if (!node.is_leaf()) {
        __builtin_prefetch(&job.nodes[BvhNode::left(node_index)]);
        __builtin_prefetch(&job.nodes[node.right()]);
    } else {
        const char* first = reinterpret_cast<const char*>(&job.leaf[node.first]);
        const char* last = reinterpret_cast<const char*>(&job.leaf[node.first + node.count]) - 1;
        for (const char* p = first; p < last; p += 64) __builtin_prefetch(p);
        __builtin_prefetch(last);
    }
}

// Fig. 3 from `root` for a stream of one ray (job.ids[0]): every op below has that one lane,
// so the ray's box fields stay in registers and no stream is partitioned; the same ops in the
// same order, and the same lane math as the wide filters, so the same bits. Most box ops of
// secondary rays deep in the tree carry one ray (63 % of them on conference, 128 x 128, 4 spp).
template <TraceDetail Detail, class Report>
SFX_LANES_INLINE void traverse_one(const TraversalJob& job, uint32_t root, Report& report_op) {
    namespace f = traversal_field;
    const float* record = job.rays + size_t(job.ids[0]) * f::record;
    const float org[3] = {record[f::org], record[f::org + 1], record[f::org + 2]};
    const float inv_dir[3] = {record[f::inv_dir], record[f::inv_dir + 1], record[f::inv_dir + 2]};
    uint32_t stack[k_traversal_stack_size];
    uint32_t depth = 0;
    stack[depth++] = root;
    while (depth != 0) {
        const uint32_t node_index = stack[--depth];
        const BvhNode& node = job.nodes[node_index];
        prefetch_below(job, node_index, node);
        float t0;  // t: the leaves below tighten it
        const bool pass = slab_test<1>(org, inv_dir, record[f::t], node.bounds, t0);
        if constexpr (Detail == TraceDetail::lanes) job.mask[0] = uint8_t(pass);
        report_op(OpKind::box_test, job.box_stage, node_index, job.ids, 1, job.mask, pass, 0);
        if (!pass) continue;
        if (node.is_leaf()) {
            timed_leaf<1, Detail>(job, node, 1, report_op);
            continue;
        }
        // The front child by the ray's sign on the split axis: box_group's vote of one lane.
        const ChildOrder order =
            child_order(node_index, node, negative_lanes<1>(inv_dir, node.axis, 1u) == 1);
        stack[depth++] = order.back;
        stack[depth++] = order.front;
    }
}

// Fig. 3 from `root` for a stream of two to four rays (job.ids[0, len)) when the trace takes no
// lanes (TraceDetail::none or counts). Short streams are most wide box ops (two or three rays in
// 46 % of them on conference, 128 x 128, 4 spp), and there the stream loop's reads, transposes
// and compresses cost more than the test. Here the rays' box fields are read into four lanes
// once, and each stream on the stack is a mask of those lanes instead of a partitioned prefix
// of ids: a stable partition keeps the passing ids in order, so a mask's lanes are the same
// stream in the same order, and the ops, their order and the lane math are the stream loop's.
// job.ids[0, len) is left as it was. t is read again after every leaf and one-ray subtree.
template <int Width, TraceDetail Detail, class Report>
SFX_LANES_INLINE void traverse_few(const TraversalJob& job, uint32_t root, uint32_t len,
                                   Report& report_op) {
    static_assert(Detail != TraceDetail::lanes, "a lanes trace lists each op's slots");
    constexpr int W = int(k_few_ray_lanes);
    namespace f = traversal_field;
    uint32_t lane_ids[W];
    for (uint32_t l = 0; l < uint32_t(W); ++l) lane_ids[l] = job.ids[l < len ? l : 0];
    // The ids of a leaf's stream or a one-ray subtree's ray, for the same code as the stream loop.
    alignas(64) uint32_t stream[W + k_stream_padding];
    TraversalJob sub = job;
    sub.ids = stream;
    BoxLanes<W> ray =
        GroupReader<W>(TraversalView{job.rays}, lane_ids, active_bits<W>(len)).read_box();
    auto read_t = [&] {
        alignas(16) float t[W];
        for (int l = 0; l < W; ++l) t[l] = job.rays[size_t(lane_ids[l]) * f::record + f::t];
        __builtin_memcpy(&ray.t, t, sizeof t);
    };
    struct Entry {
        uint32_t node, lanes;
    };
    Entry stack[k_traversal_stack_size];
    uint32_t depth = 0;
    stack[depth++] = {root, active_bits<W>(len)};
    while (depth != 0) {
        const Entry top = stack[--depth];
        const uint32_t n = uint32_t(__builtin_popcount(top.lanes));
        if (n == 1) {
            stream[0] = lane_ids[__builtin_ctz(top.lanes)];
            traverse_one<Detail>(sub, top.node, report_op);
            read_t();
            continue;
        }
        const BvhNode& node = job.nodes[top.node];
        prefetch_below(job, top.node, node);
        vfloat<W> t0;
        const uint32_t pass =
            bits<W>(slab_test<W>(ray.org, ray.inv_dir, ray.t, node.bounds, t0)) & top.lanes;
        const uint32_t k = uint32_t(__builtin_popcount(pass));
        report_op(OpKind::box_test, job.box_stage, top.node, nullptr, n, nullptr, k, 0);
        if (k == 0) continue;
        if (node.is_leaf()) {
            uint32_t m = 0;
            for (uint32_t b = pass; b != 0; b &= b - 1) stream[m++] = lane_ids[__builtin_ctz(b)];
            timed_leaf<Width, Detail>(sub, node, k, report_op);
            read_t();
            continue;
        }
        // The front child by a majority of the passing rays' direction signs, as box_group's.
        const ChildOrder order =
            child_order(top.node, node, 2 * negative_lanes<W>(ray.inv_dir, node.axis, pass) > k);
        stack[depth++] = {order.back, pass};
        stack[depth++] = {order.front, pass};
    }
}

// Fig. 3 (stream_tracer.cpp's traverse says what and why), one instruction set's width.
template <int Width, TraceDetail Detail>
void traverse(const TraversalJob& job) {
    if (job.n == 0) return;
    const BvhNode* nodes = job.nodes;
    uint32_t* ids = job.ids;
    const TraversalView view{job.rays, job.shared_origin};
    // Where the ops go: to job.sink one by one, or (TraceDetail::counts) tallied, sent at the end.
    std::conditional_t<Detail == TraceDetail::counts, OpTally, SinkReporter<Detail>> report{job};
    TraversalStackEntry stack[k_traversal_stack_size];
    uint32_t depth = 0;
    stack[depth++] = {job.entry, job.n};
    while (depth != 0) {
        const TraversalStackEntry top = stack[--depth];
        const uint32_t node_index = top.node, len = top.length;
        if (len == 1) {
            timed_short_loop(job, 0, [&] { traverse_one<Detail>(job, node_index, report); });
            continue;
        }
        if constexpr (Width >= int(k_few_ray_min_width) && Detail != TraceDetail::lanes) {
            if (len <= k_few_ray_lanes) {
                timed_short_loop(
                    job, 1, [&] { traverse_few<Width, Detail>(job, node_index, len, report); });
                continue;
            }
        }
        const BvhNode& node = nodes[node_index];
        prefetch_below(job, node_index, node);
        // The box filter (Fig. 5): passing ids first, failing ids after them (the prefix
        // [0, len) keeps its set of ids, so the streams on the stack stay valid).
        uint32_t negative = 0, front, back;
        if constexpr (Detail == TraceDetail::lanes) {  // the op lists the slots in input order
            front = box_filter<Width>(view, node.bounds, node.axis, ids, len, job.scratch,
                                      job.scratch2, job.mask, negative);
            back = len - front;
            report(OpKind::box_test, job.box_stage, node_index, ids, len, job.mask, front, 0);
            copy_ids(ids, job.scratch, front);
            copy_ids(ids + front, job.scratch2, back);
        } else {
            front = box_filter<Width>(view, node.bounds, node.axis, ids, len, ids, job.scratch,
                                      nullptr, negative);
            back = len - front;
            // Always, even if none passed: the whole-vector stores wrote over ids.
            copy_ids(ids + front, job.scratch, back);
            report(OpKind::box_test, job.box_stage, node_index, ids, len, nullptr, front, 0);
        }
        const uint32_t k = front;
        if (k == 0) continue;
        if (node.is_leaf()) {
            timed_leaf<Width, Detail>(job, node, k, report);
        } else {
            // The front child by a majority of the passing rays' direction signs.
            const ChildOrder order = child_order(node_index, node, 2 * negative > k);
            stack[depth++] = {order.back, k};
            stack[depth++] = {order.front, k};
        }
    }
    if constexpr (Detail == TraceDetail::counts) report.send();
}

template <int Width>
StreamKernels make_kernels(Isa isa) {
    StreamKernels k;
    k.isa = isa;
    k.width = Width;
    k.box_filter = &box_filter<Width>;
    k.triangle_candidates = &triangle_candidates<Width>;
    k.leaf_candidates = &leaf_candidates<Width>;
    k.sphere_filter = &sphere_filter<Width>;
    k.leaf_tests = &leaf_tests<Width>;
    k.partition = &partition<Width>;
    k.traverse[int(TraceDetail::none)] = &traverse<Width, TraceDetail::none>;
    k.traverse[int(TraceDetail::counts)] = &traverse<Width, TraceDetail::counts>;
    k.traverse[int(TraceDetail::lanes)] = &traverse<Width, TraceDetail::lanes>;
    return k;
}

}  // namespace SFX_KERNEL_ISA
}  // namespace sfx
