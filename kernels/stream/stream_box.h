#pragma once
// The slab test of intersect_box (kernels/intersect.h) over Width lanes at once, for the
// stream tracer's box filter: gathered into lane arrays, the same float operations in the
// same order per lane, so every lane's decision is intersect_box's, bit for bit (compilers
// vectorise these loops; SIMD add/mul/compare/select round exactly like the scalar ones).
//
// Why no early exit is needed: per lane t0 only grows and t1 only shrinks (NaN distances are
// replaced before they are compared), so "t0 > t1 after some axis" equals "t0 > t1 after
// the last axis". A lane passes iff intersect_box would not return INFINITY.
// stream_box_test.cpp checks the equivalence on adversarial rays and boxes.

#include <cmath>
#include <cstdint>
#include <cstring>

#include "kernels/intersect.h"

namespace sfx {

// Lane inputs in structure-of-arrays form: org, inv_dir per axis, and t_max.
template <int Width>
struct BoxLanes {
    float org[3][Width];
    float inv[3][Width];
    float t_max[Width];
};

// Four lanes as one value (GCC/Clang vector extensions: element-wise IEEE operations, and
// `mask ? a : b` selects per lane).
typedef float Float4 __attribute__((vector_size(16)));
typedef int32_t Int4 __attribute__((vector_size(16)));

inline Float4 load4(const float* p) {
    Float4 v;
    std::memcpy(&v, p, sizeof v);
    return v;
}

// out[l] = 1 iff intersect_box(ray l, b, t_max[l]) != INFINITY. Width is a multiple of 4.
template <int Width>
inline void box_test_lanes(const BoxLanes<Width>& r, const Bounds3& b, uint8_t* out) {
    static_assert(Width % 4 == 0, "box_test_lanes works in groups of four lanes");
    const Float4 inf = {INFINITY, INFINITY, INFINITY, INFINITY};
    for (int c = 0; c < Width; c += 4) {
        Float4 t0 = {0.f, 0.f, 0.f, 0.f};
        Float4 t1 = load4(r.t_max + c) * k_slab_t_max_scale;
        for (int a = 0; a < 3; ++a) {
            const Float4 lo = {b.lo[a], b.lo[a], b.lo[a], b.lo[a]};
            const Float4 hi = {b.hi[a], b.hi[a], b.hi[a], b.hi[a]};
            const Float4 inv = load4(r.inv[a] + c), org = load4(r.org[a] + c);
            Int4 inv_bits;
            std::memcpy(&inv_bits, &inv, sizeof inv_bits);
            const Int4 negative = inv_bits < 0;  // the sign bit, as std::signbit
            Float4 t_near = ((negative ? hi : lo) - org) * inv;
            Float4 t_far = ((negative ? lo : hi) - org) * inv;
            t_near = t_near != t_near ? -inf : t_near;
            t_far = t_far != t_far ? inf : t_far * k_slab_far_scale;
            t0 = t_near > t0 ? t_near : t0;
            t1 = t_far < t1 ? t_far : t1;
        }
        const Int4 pass = (t0 <= t1) & (t0 != inf);  // t0, t1 are never NaN here
        for (int l = 0; l < 4; ++l) out[c + l] = uint8_t(pass[l] != 0);
    }
}

}  // namespace sfx
