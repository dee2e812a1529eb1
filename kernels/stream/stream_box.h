#pragma once
// The slab test of intersect_box (kernels/intersect.h) over four lanes at once, for the
// stream tracer's box filter: the same float operations in the same order per lane, so each
// lane's decision is intersect_box's, bit for bit (vector add/mul/compare/select round
// exactly like the scalar ones; the tree builds with -ffp-contract=off).
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

// Four lanes as one value (GCC/Clang vector extensions: element-wise IEEE operations, and
// `mask ? a : b` selects per lane).
typedef float Float4 __attribute__((vector_size(16)));
typedef int32_t Int4 __attribute__((vector_size(16)));

// intersect_box on four gathered lanes, built in registers (a trip through memory would stall
// the vector loads on the scalar stores). Returns bit l set iff lane l passes, that is iff
// intersect_box(*r[l], b, t_max[l]) != INFINITY.
inline uint32_t box_test_gather4(const RayPrecomp* const r[4], const float t_max[4],
                                 const Bounds3& b) {
    const Float4 inf = {INFINITY, INFINITY, INFINITY, INFINITY};
    Float4 t0 = {0.f, 0.f, 0.f, 0.f};
    Float4 t1 = Float4{t_max[0], t_max[1], t_max[2], t_max[3]} * k_slab_t_max_scale;
    for (int a = 0; a < 3; ++a) {
        const Float4 lo = {b.lo[a], b.lo[a], b.lo[a], b.lo[a]};
        const Float4 hi = {b.hi[a], b.hi[a], b.hi[a], b.hi[a]};
        const Float4 org = {r[0]->org[a], r[1]->org[a], r[2]->org[a], r[3]->org[a]};
        const Float4 inv = {r[0]->inv_dir[a], r[1]->inv_dir[a], r[2]->inv_dir[a],
                            r[3]->inv_dir[a]};
        Int4 inv_bits;
        std::memcpy(&inv_bits, &inv, sizeof inv_bits);
        const Int4 negative = inv_bits < 0;
        Float4 t_near = ((negative ? hi : lo) - org) * inv;
        Float4 t_far = ((negative ? lo : hi) - org) * inv;
        t_near = t_near != t_near ? -inf : t_near;
        t_far = t_far != t_far ? inf : t_far * k_slab_far_scale;
        t0 = t_near > t0 ? t_near : t0;
        t1 = t_far < t1 ? t_far : t1;
    }
    const Int4 pass = (t0 <= t1) & (t0 != inf);
    return uint32_t(pass[0] & 1) | uint32_t(pass[1] & 2) | uint32_t(pass[2] & 4) |
           uint32_t(pass[3] & 8);
}

}  // namespace sfx
