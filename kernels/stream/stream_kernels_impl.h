#pragma once
// The width-generic source of the stream kernels (stream_kernels.h). Included by exactly one
// translation unit per instruction set, which defines SFX_KERNEL_ISA (the namespace its
// instantiations live in) and is compiled with that instruction set's flags: stream_kernels.cpp
// (scalar, Width 1), stream_kernels_avx2.cpp (Width 8), stream_kernels_avx512.cpp (Width 16).
// Only always-inline lane operations and the shared ray math of intersect.h are used here,
// so no out-of-line function compiled with wide instructions escapes its namespace.

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

// Calls group(std::integral_constant<int, W>(), g) for each group of Width ids from g = 0 while
// g < n. At 16 lanes a last group of at most 8 ids (a short stream, or a stream's tail) runs at
// 8: half the reads on short secondary streams; the lane math is the same at every width, so
// are the results.
template <int Width, class Group>
SFX_LANES_INLINE void for_each_group(uint32_t n, Group&& group) {
    for (uint32_t g = 0; g < n; g += Width) {
        if constexpr (Width == 16) {
            if (n - g <= 8) return group(std::integral_constant<int, 8>(), g);
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

    SFX_LANES_INLINE GroupReader(TraversalView rays, vint<Width> ids) : data(rays.data), id(ids) {
        const vint<Width> o = id * broadcast_int<Width>(traversal_field::record);
        __builtin_memcpy(offset, &o, sizeof offset);
    }
    // The box test's half of every lane's record.
    SFX_LANES_INLINE BoxLanes<Width> read_box() const {
        namespace f = traversal_field;
        vfloat<Width> h[8];
        load_transposed8<Width>(data + f::box_half, offset, h);
        return {{h[f::org], h[f::org + 1], h[f::org + 2]},
                {h[f::inv_dir], h[f::inv_dir + 1], h[f::inv_dir + 2]},
                h[f::t]};
    }
    // The triangle test's half of every lane's record.
    SFX_LANES_INLINE TriangleLanes<Width> read_triangle() const {
        namespace f = traversal_field;
        vfloat<Width> h[8];
        load_transposed8<Width>(data + f::triangle_half, offset, h);
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

// One group of box_filter: the `left` ids from ids on (all of them if left >= Width).
template <int Width>
SFX_LANES_INLINE void box_group(TraversalView rays, const Bounds3& box, int axis,
                                const uint32_t* ids, uint32_t left, uint32_t* pass_out,
                                uint32_t* fail_out, uint8_t* mask, uint32_t& front, uint32_t& back,
                                uint32_t& negatives) {
    const uint32_t active = active_bits<Width>(left);
    const GroupReader<Width> r(rays, load_ids<Width>(ids, active));
    const BoxLanes<Width> ray = r.read_box();
    vfloat<Width> t0;
    const uint32_t pass =
        bits<Width>(slab_test<Width>(ray.org, ray.inv_dir, ray.t, box, t0)) & active;
    // dir < 0 on the split axis: inv_dir < 0, except inv_dir = -inf (dir = -0; RayPrecomp
    // flushes denormals, so a negative normal dir has a finite inverse).
    const vfloat<Width> inv = axis == 0   ? ray.inv_dir[0]
                              : axis == 1 ? ray.inv_dir[1]
                                          : ray.inv_dir[2];
    const vfloat<Width> zero = broadcast<Width>(0.f), minus_inf = broadcast<Width>(-INFINITY);
    negatives += uint32_t(__builtin_popcount(
        bits<Width>(mask_and<vbool<Width>>(inv < zero, inv != minus_inf)) & pass));
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
    for_each_group<Width>(n, [&](auto width, uint32_t g) {
        box_group<decltype(width)::value>(rays, box, axis, ids + g, n - g, pass_out, fail_out,
                                          mask ? mask + g : nullptr, front, back, negatives);
    });
    negative += negatives;
    return front;
}

template <int Width>
uint32_t triangle_candidates(TraversalView rays, const Vec3& p0, const Vec3& p1, const Vec3& p2,
                             const uint32_t* ids, uint32_t n, uint32_t* positions) {
    uint32_t k = 0;
    for (uint32_t g = 0; g < n; g += Width) {
        const uint32_t active = active_bits<Width>(n - g);
        const GroupReader<Width> r(rays, load_ids<Width>(ids + g, active));
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
    const GroupReader<Width> r(rays, load_ids<Width>(ids + g, active));
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
    if (back != 0) std::memcpy(ids + front, scratch, back * sizeof(uint32_t));
    return front;
}

template <int Width>
StreamKernels make_kernels(Isa isa) {
    StreamKernels k;
    k.isa = isa;
    k.width = Width;
    k.box_filter = &box_filter<Width>;
    k.triangle_candidates = &triangle_candidates<Width>;
    k.leaf_candidates = &leaf_candidates<Width>;
    k.partition = &partition<Width>;
    return k;
}

}  // namespace SFX_KERNEL_ISA
}  // namespace sfx
