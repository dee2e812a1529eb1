#pragma once
// Robust ray/box, ray/triangle and ray/sphere tests, written once and called by every tracer.
// - Boxes: conservative slab test (Ize, "Robust BVH Ray Traversal", JCGT 2013).
// - Triangles: watertight test (Woop, Benthin, Wald, JCGT 2013): no ray slips between
//   triangles sharing an edge or vertex.
// - Spheres: the numerically careful quadratic of Haines et al. (Ray Tracing Gems, ch. 7).
// - Spawned rays: origins pushed off surfaces (Waechter & Binder, Ray Tracing Gems, ch. 6).

#include <emmintrin.h>  // SSE2: one ray's slab test and bit operations (slab_entry_exit,
                        // next_floats_towards)

#include <algorithm>
#include <cfloat>
#include <cmath>
#include <cstddef>
#include <cstring>
#include <limits>
#include <type_traits>

#include "kernels/ray.h"
#include "kernels/simd/lanes.h"
#include "workloads/scene.h"

namespace sfx {

inline uint32_t float_bits(float f) {
    uint32_t i;
    std::memcpy(&i, &f, 4);
    return i;
}
inline float bits_float(uint32_t i) {
    float f;
    std::memcpy(&f, &i, 4);
    return f;
}

// Per-ray constants of the watertight triangle test and the slab test.
struct RayPrecomp {
    Vec3 org;
    Vec3 dir;      // denormal components flushed to (signed) zero
    Vec3 inv_dir;  // may hold +-inf; the slab test is written for that
    int kx = 0, ky = 1, kz = 2;
    float sx = 0.f, sy = 0.f, sz = 0.f;

    // Every traced ray is set up here, and a frame's scattered rays point anywhere: the flush,
    // the axis and the swap are chosen by comparisons that feed arithmetic, not jumps, so a
    // ray's cost does not follow its direction (with jumps, set-up cost 29 TSC ticks a camera
    // ray and 60 a scattered one in furnace's frames; without, 41 a ray on average; AMD Zen 4
    // VM, 2026-12-03). The same bits as max_axis, the ternaries and std::swap
    // (tests/kernels/geometry_robust_test.cpp).
    explicit RayPrecomp(const Ray& r) : org(r.org) {
        const auto flush = [](float d) {  // a denormal to the zero of its sign
            const uint32_t tiny = 0u - uint32_t(std::fabs(d) < FLT_MIN);
            return bits_float(float_bits(d) & ~(tiny & 0x7fffffffu));
        };
        dir = {flush(r.dir.x), flush(r.dir.y), flush(r.dir.z)};
        inv_dir = {1.f / dir.x, 1.f / dir.y, 1.f / dir.z};
        // max_axis(abs(dir)): x if |x| >= |y| and |x| >= |z|, else y if |y| >= |z|, else z.
        const float ax = std::fabs(dir.x), ay = std::fabs(dir.y), az = std::fabs(dir.z);
        const int x_over_y = int(ax >= ay), x_over_z = int(ax >= az), y_over_z = int(ay >= az);
        kz = x_over_y * (2 - 2 * x_over_z) + (1 - x_over_y) * (2 - y_over_z);
        static constexpr int next_axis[3] = {1, 2, 0};
        kx = next_axis[kz];
        ky = next_axis[kx];
        const float d[3] = {dir.x, dir.y, dir.z}, inv[3] = {inv_dir.x, inv_dir.y, inv_dir.z};
        const int flip = (kx ^ ky) & -int(d[kz] < 0.f);  // keep the winding of the triangle test
        kx ^= flip;
        ky ^= flip;
        sx = d[kx] / d[kz];
        sy = d[ky] / d[kz];
        sz = inv[kz];  // 1.f / dir[kz], computed above
    }
};

// gamma(n) of Higham/pbrt: bound on the relative error of n roundings.
constexpr float gamma_bound(int n) {
    return (float(n) * (FLT_EPSILON * 0.5f)) / (1.f - float(n) * (FLT_EPSILON * 0.5f));
}

// Ize: the far slab distances are rounded outwards by 1 + 2 gamma(3).
constexpr float k_slab_far_scale = 1.f + 2.f * gamma_bound(3);
// Boxes are compared against the current closest t with extra room: a primitive's computed t
// may lie a few ulps before the computed entry of a box that contains it (a triangle on a box
// face, equal-t ties). Culling such a box would make the closest hit depend on traversal order.
constexpr float k_slab_t_max_scale = 1.f + 1.f / 65536.f;

// The origin of a slab test whose lanes share it (a pinhole camera's primary rays) and whose
// box is given relative to it: the caller subtracts the origin from the planes once per box,
// not once per lane; the same subtraction, so the same bits.
struct BoxRelativeToOrigin {};

// Box planes on axis a (one per lane) relative to the lanes' origins.
template <int Width>
SFX_LANES_INLINE vfloat<Width> minus_origin(vfloat<Width> plane, const vfloat<Width> (&org)[3],
                                            int a) {
    return plane - org[a];
}
template <int Width>
SFX_LANES_INLINE vfloat<Width> minus_origin(vfloat<Width> plane, BoxRelativeToOrigin, int) {
    return plane;
}

// The slab's near and far planes on one axis, per lane: (hi, lo) where the direction is
// negative (its inverse's sign bit set: -0 too), else (lo, hi). Wide lanes only: one ray's
// test (slab_entry_exit) picks them by the same bit operations on its three axes at once.
template <int Width>
SFX_LANES_INLINE void planes_by_sign(vfloat<Width> inv_dir, float lo, float hi,
                                     vfloat<Width>& near_plane, vfloat<Width>& far_plane) {
    static_assert(Width > 1, "one ray: slab_entry_exit");
    const vbool<Width> negative = sign_bit<Width>(inv_dir);
    const vfloat<Width> lo_lanes = broadcast<Width>(lo), hi_lanes = broadcast<Width>(hi);
    near_plane = select(negative, hi_lanes, lo_lanes);
    far_plane = select(negative, lo_lanes, hi_lanes);
}

// One ray's slab test (slab_test's rule) with its three axes in the lanes of SSE registers:
// the entry distance, or INFINITY where the ray misses. The same bits as the per-axis form:
// t0 is the largest of 0 and the axes' non-NaN near distances in any order (MAXPS keeps the
// second operand, 0, for a NaN or a -0), and t1 the smallest of t_max's and the far ones,
// compared only with t0 (a zero's sign does not change a compare). The fourth lane's direction
// is a NaN, so that its distances leave both alone. Per axis, GCC compiled the first axis's
// `t_near > 0 ? t_near : 0` to a jump, mispredicted on boxes that rays start on both sides of
// and seldom in a frame: the scalar box test cost 41-57 cycles a lane on the microbenchmarks'
// nodes below the root's children and 25-29 on the root and its children, which no per-op cost
// and no trace carried (selects in its place cost 19-27 % more on the frames' traversals). In
// SSE lanes it costs 20-24 cycles a lane on every node, and the scalar traversals of furnace,
// cornell and conference take 2 %, 11-19 % and 18-23 % fewer ticks; AVX2's (its one-ray loop)
// 0 to 7 % fewer (AMD Zen 4 VM, 2026-12-04).
template <class Origin>
SFX_LANES_INLINE float slab_entry_exit(const Origin& org, const float inv_dir[3], float t_max,
                                       const Bounds3& b) {
    const __m128 inv = _mm_setr_ps(inv_dir[0], inv_dir[1], inv_dir[2], NAN);
    // Two loads inside the box's six floats: (lo, hi.x) and (lo.z, hi) turned to (hi, lo.z);
    // the fourth lanes are left alone by the NaN.
    static_assert(sizeof(Bounds3) == 6 * sizeof(float) && offsetof(Bounds3, hi) == 12,
                  "Bounds3: lo then hi, three floats each");
    __m128 lo = _mm_loadu_ps(&b.lo.x);
    __m128 hi = _mm_loadu_ps(&b.lo.z);
    hi = _mm_shuffle_ps(hi, hi, _MM_SHUFFLE(0, 3, 2, 1));
    if constexpr (!std::is_same_v<Origin, BoxRelativeToOrigin>) {
        const __m128 o = _mm_setr_ps(org[0], org[1], org[2], 0.f);
        lo = _mm_sub_ps(lo, o);
        hi = _mm_sub_ps(hi, o);
    }
    // The planes by the direction's sign bit (-0 too), as planes_by_sign: not by
    // `negative ? hi : lo`, which GCC compiles to a jump that mispredicts on rays of mixed
    // directions (the scalar box filter's cost a lane followed the rays' directions, 1 : 2.3 :
    // 5.2 for rays of one sign, of random x signs, of random signs on every axis; 1.5 on all
    // three by bit operations; AMD Zen 5 VM, 2026-11-27).
    const __m128 negative = _mm_castsi128_ps(_mm_srai_epi32(_mm_castps_si128(inv), 31));
    const __m128 swap = _mm_and_ps(_mm_xor_ps(lo, hi), negative);
    const __m128 t_near = _mm_mul_ps(_mm_xor_ps(lo, swap), inv);
    const __m128 t_far =
        _mm_mul_ps(_mm_mul_ps(_mm_xor_ps(hi, swap), inv), _mm_set1_ps(k_slab_far_scale));
    __m128 t0 = _mm_max_ps(t_near, _mm_setzero_ps());
    __m128 t1 = _mm_min_ps(t_far, _mm_set1_ps(t_max * k_slab_t_max_scale));
    t0 = _mm_max_ps(t0, _mm_shuffle_ps(t0, t0, _MM_SHUFFLE(1, 0, 3, 2)));
    t0 = _mm_max_ps(t0, _mm_shuffle_ps(t0, t0, _MM_SHUFFLE(2, 3, 0, 1)));
    t1 = _mm_min_ps(t1, _mm_shuffle_ps(t1, t1, _MM_SHUFFLE(1, 0, 3, 2)));
    t1 = _mm_min_ps(t1, _mm_shuffle_ps(t1, t1, _MM_SHUFFLE(2, 3, 0, 1)));
    const __m128 enters = _mm_cmple_ss(t0, t1);
    return _mm_cvtss_f32(
        _mm_or_ps(_mm_and_ps(enters, t0), _mm_andnot_ps(enters, _mm_set_ss(INFINITY))));
}

// Slab test over [0, t_max] for Width rays against one box, one rule for the reference tracer
// and the stream filters (kernels/stream/stream_kernels_impl.h); one ray (Width 1) takes its
// three axes in SSE lanes (slab_entry_exit), the wide lanes an axis at a time. A lane passes
// iff its ray enters the box; t0 is the entry distance of passing lanes.
// The near and far planes are chosen by the sign of the direction (-0 counts as negative), so
// no swap is needed. The only NaN source, 0 * inf, means the origin lies on a slab plane and the
// ray runs inside that plane: the plane then bounds nothing (the box is closed, so it is kept),
// which the compares give by themselves: a NaN distance fails both, so t0 and t1 keep their
// values, as if it were -inf (near) or +inf (far).
// No early exit per axis: t0 only grows and t1 only shrinks, so "t0 > t1 after some axis"
// equals "t0 > t1 after the last axis".
// `org`: each lane's origin (vfloat<Width>[3]), or BoxRelativeToOrigin.
template <int Width, class Origin>
SFX_LANES_INLINE vbool<Width> slab_test(const Origin& org, const vfloat<Width> inv_dir[3],
                                        vfloat<Width> t_max, const Bounds3& b, vfloat<Width>& t0) {
    const vfloat<Width> inf = broadcast<Width>(INFINITY);
    if constexpr (Width == 1) {
        t0 = slab_entry_exit(org, inv_dir, t_max, b);
        return t0 != inf;
    } else {
        t0 = broadcast<Width>(0.f);
        vfloat<Width> t1 = t_max * k_slab_t_max_scale;
        for (int a = 0; a < 3; ++a) {
            vfloat<Width> near_plane, far_plane;
            planes_by_sign<Width>(inv_dir[a], b.lo[a], b.hi[a], near_plane, far_plane);
            const vfloat<Width> t_near = minus_origin<Width>(near_plane, org, a) * inv_dir[a];
            const vfloat<Width> t_far =
                minus_origin<Width>(far_plane, org, a) * inv_dir[a] * k_slab_far_scale;
            t0 = select(t_near > t0, t_near, t0);
            t1 = select(t_far < t1, t_far, t1);
        }
        return mask_and<vbool<Width>>(t0 <= t1, t0 != inf);
    }
}

// The slab test for one ray. Returns the entry distance, or INFINITY on a miss.
inline float intersect_box(const RayPrecomp& r, const Bounds3& b, float t_max) {
    const float org[3] = {r.org.x, r.org.y, r.org.z};
    const float inv_dir[3] = {r.inv_dir.x, r.inv_dir.y, r.inv_dir.z};
    float t0;
    return slab_test<1>(org, inv_dir, t_max, b, t0) ? t0 : INFINITY;
}

// One primitive of Bvh::prim_ids' order (kernels/bvh.h) with its triangle's vertices beside it: a
// leaf's primitives are one contiguous block, read without going through prim_ids, Scene::triangles
// and Scene::positions (three dependent cache misses a primitive on scattered rays). A
// sphere's vertices are unused. The same vertex values, so the same bits.
struct LeafPrimitive {
    Vec3 p0, p1, p2;
    uint32_t prim = 0;
};
static_assert(sizeof(LeafPrimitive) == 40, "LeafPrimitive: three vertices and an id");

// The first stage of the watertight triangle test (Woop et al.) for Width rays against one
// triangle, shared by intersect_triangle (Width 1) and the stream's triangle filter: the
// vertices relative to the origin, sheared so the ray runs along +z, and the scaled
// barycentrics u, v, w (edge functions) in float.
template <int Width>
struct ShearedTriangle {
    vfloat<Width> ax, ay, bx, by, cx, cy;  // sheared x, y of the vertices
    vfloat<Width> akz, bkz, ckz;           // unsheared distance along the major axis
    vfloat<Width> u, v, w;
};

template <int Width>
SFX_LANES_INLINE vfloat<Width> pick_axis(vint<Width> k, vfloat<Width> x, vfloat<Width> y,
                                         vfloat<Width> z) {
    if constexpr (Width == 1) {
        // Indexed, not by jumps (GCC's code for the selects), which mispredict where the major
        // axis changes from ray to ray: the scalar triangle filter cost 2.3-2.8 times as much
        // a lane on rays of random major axes as on rays of one (AMD Zen 5 VM, 2026-11-27);
        // indexed, 0.8-0.95 of the latter on both.
        const float axes[3] = {x, y, z};
        return axes[k];
    } else {
        return select(k == 0, x, select(k == 1, y, z));
    }
}

// One vertex relative to the origin, sheared: x, y and the distance along the major axis.
template <int Width>
SFX_LANES_INLINE void shear_vertex(const vfloat<Width> org[3], vint<Width> kx, vint<Width> ky,
                                   vint<Width> kz, vfloat<Width> sx, vfloat<Width> sy,
                                   const Vec3& p, vfloat<Width>& x, vfloat<Width>& y,
                                   vfloat<Width>& along_kz) {
    const vfloat<Width> dx = broadcast<Width>(p.x) - org[0];
    const vfloat<Width> dy = broadcast<Width>(p.y) - org[1];
    const vfloat<Width> dz = broadcast<Width>(p.z) - org[2];
    along_kz = pick_axis<Width>(kz, dx, dy, dz);
    x = pick_axis<Width>(kx, dx, dy, dz) - sx * along_kz;
    y = pick_axis<Width>(ky, dx, dy, dz) - sy * along_kz;
}

template <int Width>
SFX_LANES_INLINE ShearedTriangle<Width> shear_triangle(const vfloat<Width> org[3], vint<Width> kx,
                                                       vint<Width> ky, vint<Width> kz,
                                                       vfloat<Width> sx, vfloat<Width> sy,
                                                       const Vec3& p0, const Vec3& p1,
                                                       const Vec3& p2) {
    ShearedTriangle<Width> s;
    shear_vertex<Width>(org, kx, ky, kz, sx, sy, p0, s.ax, s.ay, s.akz);
    shear_vertex<Width>(org, kx, ky, kz, sx, sy, p1, s.bx, s.by, s.bkz);
    shear_vertex<Width>(org, kx, ky, kz, sx, sy, p2, s.cx, s.cy, s.ckz);
    s.u = s.cx * s.by - s.cy * s.bx;
    s.v = s.ax * s.cy - s.ay * s.cx;
    s.w = s.bx * s.ay - s.by * s.ax;
    return s;
}

// True only where the watertight test rejects on the float edge functions alone (strictly
// mixed signs, none zero: a zero is decided in double by intersect_triangle).
template <int Width>
SFX_LANES_INLINE vbool<Width> edges_reject(const ShearedTriangle<Width>& s) {
    using M = vbool<Width>;
    const vfloat<Width> zero = broadcast<Width>(0.f);
    const M nonzero = mask_and<M>(mask_and<M>(s.u != zero, s.v != zero), s.w != zero);
    const M some_negative = mask_or<M>(mask_or<M>(s.u < zero, s.v < zero), s.w < zero);
    const M some_positive = mask_or<M>(mask_or<M>(s.u > zero, s.v > zero), s.w > zero);
    return mask_and<M>(nonzero, mask_and<M>(some_negative, some_positive));
}

// The plane normal (p1 - p0) x (p2 - p0) in double, from the input floats directly. The cross
// product is exact whenever the coordinate differences are (exponents within 29 bits of each
// other), so exactly collinear vertices give exactly zero.
struct TriangleNormal {
    double x, y, z;
    bool zero() const { return x == 0.0 && y == 0.0 && z == 0.0; }
};

SFX_LANES_INLINE TriangleNormal triangle_normal(const Vec3& p0, const Vec3& p1, const Vec3& p2) {
    const double e1x = double(p1.x) - double(p0.x), e1y = double(p1.y) - double(p0.y),
                 e1z = double(p1.z) - double(p0.z);
    const double e2x = double(p2.x) - double(p0.x), e2y = double(p2.y) - double(p0.y),
                 e2z = double(p2.z) - double(p0.z);
    return {e1y * e2z - e1z * e2y, e1z * e2x - e1x * e2z, e1x * e2y - e1y * e2x};
}

inline bool triangle_is_degenerate(const Vec3& p0, const Vec3& p1, const Vec3& p2) {
    return triangle_normal(p0, p1, p2).zero();
}

// Watertight ray/triangle test. On a hit with 0 < t <= t_max fills t, u, v and returns true.
// - Front and back faces are hit alike (dielectrics need both).
// - t > 0 is decided conservatively. The computed t is a convex combination of the vertices'
//   computed z (distance along the ray's major axis): when all of them are ahead beyond their
//   rounding, so is the hit. Otherwise the triangle reaches back to the origin (a spawned
//   ray's own surface or its neighbours), and the side of the plane the origin is on is
//   decided in double from the input floats. An origin offset to one side of its surface
//   (offset_ray_origin) therefore never re-hits that surface.
// - Degenerate (zero-area) triangles never hit. In sheared ray space collinear vertices are no
//   longer exactly collinear, so the determinant alone does not catch them.
// Both double-precision checks run only for candidates that passed every float test.
// `n`: triangle_normal(p0, p1, p2), computed once by a caller that tests many rays against the
// triangle (the stream's candidates of a leaf op).
inline bool intersect_triangle(const RayPrecomp& r, const Vec3& p0, const Vec3& p1, const Vec3& p2,
                               const TriangleNormal& n, float t_max, float& t_out, float& u_out,
                               float& v_out) {
    const float org[3] = {r.org.x, r.org.y, r.org.z};
    const ShearedTriangle<1> s = shear_triangle<1>(org, r.kx, r.ky, r.kz, r.sx, r.sy, p0, p1, p2);
    const float ax = s.ax, ay = s.ay, bx = s.bx, by = s.by, cx = s.cx, cy = s.cy;
    float u = s.u, v = s.v, w = s.w;
    if (u == 0.f || v == 0.f || w == 0.f) {  // on an edge: decide in double, as the paper does
        u = float(double(cx) * double(by) - double(cy) * double(bx));
        v = float(double(ax) * double(cy) - double(ay) * double(cx));
        w = float(double(bx) * double(ay) - double(by) * double(ax));
    }
    if ((u < 0.f || v < 0.f || w < 0.f) && (u > 0.f || v > 0.f || w > 0.f)) return false;
    const float det = u + v + w;
    if (det == 0.f || !std::isfinite(det)) return false;
    const float az = r.sz * s.akz, bz = r.sz * s.bkz, cz = r.sz * s.ckz;
    const float t_scaled = u * az + v * bz + w * cz;
    if (det < 0.f ? t_scaled >= 0.f : t_scaled <= 0.f) return false;  // t <= 0
    // The watertight test decides inside/outside and the sign of t; t itself comes from the
    // plane equation in double: the scaled-barycentric t loses digits on slivers (0.4 % on a
    // 20 x 0.05 triangle), the plane's does not. Products of floats are exact in double, so
    // coplanar triangles report bit-equal t and their ties go to the lower id.
    const double n_dot_d = n.x * r.dir.x + n.y * r.dir.y + n.z * r.dir.z;
    const double n_dot_a = n.x * (double(p0.x) - r.org.x) + n.y * (double(p0.y) - r.org.y) +
                           n.z * (double(p0.z) - r.org.z);
    float t = n_dot_d != 0.0 ? float(n_dot_a / n_dot_d) : t_scaled / det;
    if (!(t > 0.f)) t = std::numeric_limits<float>::denorm_min();  // the sign test above rules
    // Range test on the final t only: a test on t * det would round differently and could
    // drop a candidate whose t equals t_max (an equal-t tie that the lower id must win).
    if (!(t <= t_max) || !std::isfinite(t)) return false;
    // z = a[kz] / dir[kz] carries at most 3 roundings (a, sz, the product).
    const float min_z = std::min(az, std::min(bz, cz));
    const bool all_ahead = min_z > gamma_bound(4) * std::max(std::fabs(bz), std::fabs(cz)) &&
                           min_z > gamma_bound(4) * std::fabs(az);
    if (n.zero()) return false;  // degenerate
    // Otherwise the origin's side of the plane, decided in double: the ray meets the plane at
    // t > 0.
    if (!all_ahead && !((n_dot_a > 0.0 && n_dot_d > 0.0) || (n_dot_a < 0.0 && n_dot_d < 0.0)))
        return false;
    const float inv_det = 1.f / det;
    t_out = t;
    u_out = v * inv_det;  // weight of p1
    v_out = w * inv_det;  // weight of p2
    return true;
}

inline bool intersect_triangle(const RayPrecomp& r, const Vec3& p0, const Vec3& p1, const Vec3& p2,
                               float t_max, float& t_out, float& u_out, float& v_out) {
    return intersect_triangle(r, p0, p1, p2, triangle_normal(p0, p1, p2), t_max, t_out, u_out,
                              v_out);
}

// Ray/sphere test over (0, t_max] for Width rays against one sphere, written once for the
// reference tracer (Width 1) and the stream's sphere filter: a lane hits iff a root lies in
// range; t is then the nearest such root.
// An origin within rounding error of the surface (a spawned ray) is treated as on it: the root
// near 0 is the surface being left and is dropped, so a ray leaving outwards misses and a ray
// leaving inwards hits the far side, whichever side of the surface the origin rounded to.
// Lanes that have already missed are computed on (their NaNs are masked off); a group none of
// whose lanes has a real discriminant stops there.
template <int Width>
SFX_LANES_INLINE vbool<Width> sphere_test(const vfloat<Width> org[3], const vfloat<Width> dir[3],
                                          vfloat<Width> t_max, const Sphere& s, vfloat<Width>& t) {
    using M = vbool<Width>;
    const vfloat<Width> zero = broadcast<Width>(0.f), inf = broadcast<Width>(INFINITY);
    const vfloat<Width> fx = org[0] - broadcast<Width>(s.center.x),
                        fy = org[1] - broadcast<Width>(s.center.y),
                        fz = org[2] - broadcast<Width>(s.center.z);
    const vfloat<Width> a = dir[0] * dir[0] + dir[1] * dir[1] + dir[2] * dir[2];
    const vfloat<Width> b_half = -(fx * dir[0] + fy * dir[1] + fz * dir[2]);  // -b/2
    // Discriminant from the distance of the ray's closest approach (Haines et al. eq. 7.5).
    const vfloat<Width> along = b_half / a;
    const vfloat<Width> lx = fx + dir[0] * along, ly = fy + dir[1] * along,
                        lz = fz + dir[2] * along;
    const vfloat<Width> r2 = broadcast<Width>(s.radius * s.radius);
    const vfloat<Width> disc = a * (r2 - (lx * lx + ly * ly + lz * lz));
    M hit = disc >= zero;
    if (none<Width>(hit)) return hit;
    const vfloat<Width> q = b_half + copy_sign<Width>(square_root<Width>(disc), b_half);
    hit = mask_and<M>(hit, q != zero);  // q = 0: tangent at the origin
    const vfloat<Width> f2 = fx * fx + fy * fy + fz * fz;
    const vfloat<Width> c = f2 - r2;  // |f|^2 - r^2: the origin's side of the surface
    constexpr float surface_bound = gamma_bound(8);  // a constant: no call in the wide kernels
    const M on_surface = magnitude<Width>(c) <= broadcast<Width>(surface_bound) * (f2 + r2);
    // Stable pair of roots: c / q is the one near 0 when the origin is near the surface.
    const vfloat<Width> t_near_origin = c / q, t_other = q / a;
    const vfloat<Width> t_first = select(on_surface, inf, t_near_origin);
    const M swap = t_first > t_other;
    const vfloat<Width> t0 = select(swap, t_other, t_first), t1 = select(swap, t_first, t_other);
    const M first = mask_and<M>(t0 > zero, t0 <= t_max);
    const M second = mask_and<M>(mask_and<M>(t1 > zero, t1 <= t_max), magnitude<Width>(t1) < inf);
    t = select(first, t0, t1);
    return mask_and<M>(hit, mask_or<M>(first, second));
}

// The sphere test for one ray; on a hit fills t_out.
inline bool intersect_sphere(const RayPrecomp& r, const Sphere& s, float t_max, float& t_out) {
    const float org[3] = {r.org.x, r.org.y, r.org.z}, dir[3] = {r.dir.x, r.dir.y, r.dir.z};
    float t;
    if (!sphere_test<1>(org, dir, t_max, s, t)) return false;
    t_out = t;
    return true;
}

// Waechter & Binder: move p off the surface along n (the side the new ray leaves from),
// by a fixed number of ulps far from the origin and by a fixed distance near it.
// Sufficient when p's error is a few ulps of p itself; a hit near the world origin on a
// triangle with far-away vertices has a larger error: use the SurfaceHit overload below.
inline Vec3 offset_ray_origin(const Vec3& p, const Vec3& n) {
    constexpr float k_origin = 1.f / 32.f, k_float_scale = 1.f / 65536.f, k_int_scale = 256.f;
    Vec3 out;
    for (int a = 0; a < 3; ++a) {
        const int of = int(k_int_scale * n[a]);
        // In uint32_t: the same bits as the int sum, without its overflow at p = -0 (whose
        // result the float branch below replaces).
        const float pi = bits_float(float_bits(p[a]) + uint32_t(p[a] < 0.f ? -of : of));
        out[a] = std::fabs(p[a]) < k_origin ? p[a] + k_float_scale * n[a] : pi;
    }
    return out;
}

// Per lane, std::nextafter(x, +inf) where s > 0, std::nextafter(x, -inf) where s < 0, else
// (s zero or NaN) x: the same bits, by bit operations on four lanes at once. Every scattered
// ray's origin takes three of these (offset_ray_origin); by the comparisons and library calls
// before, its cost followed the signs of the surface normals, which no per-op cost or trace
// carries: by bit operations, lambertian_direct costs 38 % less a lane and lambertian_indirect
// 33 % less on furnace's sphere, whose normals point anywhere, and 1 % more and 10 % less on
// cornell's walls, along a few axes (AMD Zen 4 VM, 2026-12-03).
SFX_LANES_INLINE __m128 next_floats_towards(__m128 x, __m128 s) {
    const __m128 zero_f = _mm_setzero_ps();
    const __m128i sign = _mm_set1_epi32(int(0x80000000u)), one = _mm_set1_epi32(1);
    const __m128i inf = _mm_set1_epi32(0x7f800000);
    // Stepping x down is stepping -x up, then negating back.
    const __m128i down = _mm_and_si128(_mm_castps_si128(_mm_cmplt_ps(s, zero_f)), sign);
    const __m128i u = _mm_xor_si128(_mm_castps_si128(x), down);
    const __m128i magnitude = _mm_andnot_si128(sign, u);
    // Up: a positive value's bits + 1, a negative one's - 1, +-0 to the least denormal.
    const __m128i step = _mm_or_si128(_mm_srai_epi32(u, 31), one);
    const __m128i is_zero = _mm_cmpeq_epi32(magnitude, _mm_setzero_si128());
    const __m128i up = _mm_or_si128(_mm_andnot_si128(is_zero, _mm_add_epi32(u, step)),
                                    _mm_and_si128(is_zero, one));
    // Kept: lanes with no step (s zero or NaN), and +inf and NaN, which up leaves alone.
    const __m128i steps =
        _mm_castps_si128(_mm_or_ps(_mm_cmpgt_ps(s, zero_f), _mm_cmplt_ps(s, zero_f)));
    const __m128i stays = _mm_or_si128(_mm_cmpeq_epi32(u, inf), _mm_cmpgt_epi32(magnitude, inf));
    const __m128i take = _mm_andnot_si128(stays, steps);
    const __m128i r = _mm_or_si128(_mm_and_si128(take, up), _mm_andnot_si128(take, u));
    return _mm_castsi128_ps(_mm_xor_si128(r, down));
}

// Error-bound offset (pbrt-v4 OffsetRayOrigin): p lies within +-p_error (per component) of the
// true surface, so moving it by dot(|n|, p_error) along n, then one more float outwards per
// component, puts it strictly on n's side. Together with the conservative t > 0 tests above,
// no ray leaving on that side can re-hit the surface it starts on.
inline Vec3 offset_ray_origin(const Vec3& p, const Vec3& p_error, const Vec3& n) {
    const float d = dot(abs(n), p_error);
    const Vec3 offset = n * d;
    const Vec3 sum = p + offset;
    alignas(16) float out[4];
    _mm_store_ps(out, next_floats_towards(_mm_setr_ps(sum.x, sum.y, sum.z, 0.f),
                                          _mm_setr_ps(offset.x, offset.y, offset.z, 0.f)));
    return {out[0], out[1], out[2]};
}

// Error bounds of surface points, for offset_ray_origin(p, p_error, n).
// A point p0 w + p1 u + p2 v: any weights summing to 1 give a point of the plane, and
// w = 1 - u - v makes the sum 1 to a rounding, so the error is the weighted sum's (pbrt-v4).
inline Vec3 triangle_point_error(const Vec3& p0, const Vec3& p1, const Vec3& p2, float w, float u,
                                 float v) {
    return (abs(p0 * w) + abs(p1 * u) + abs(p2 * v)) * gamma_bound(7);
}
// A point center + n * radius with n normalized in float.
inline Vec3 sphere_point_error(const Vec3& center, const Vec3& n, float radius) {
    return (abs(center) + abs(n * radius)) * gamma_bound(6);
}

// Surface data at a hit, computed the same way by every tracer.
struct SurfaceHit {
    Vec3 position;
    Vec3 position_error;     // |position - true surface point| <= position_error, per component
    Vec3 normal;             // geometric, unit length, facing against the incoming ray
    bool front_face = true;  // the ray arrived from the side the stored normal points to
    uint32_t material = 0;
};

// Prefetches of what surface_at(scene, ray, hit) reads for hit.prim: its triangle record, then
// (once that has arrived) its vertices. A sphere's record is small and read by few rays.
inline void prefetch_surface_triangle(const Scene& scene, uint32_t prim) {
    if (!scene.is_sphere(prim)) __builtin_prefetch(&scene.triangles[prim]);
}
inline void prefetch_surface_vertices(const Scene& scene, uint32_t prim) {
    if (scene.is_sphere(prim)) return;
    const Triangle& tri = scene.triangles[prim];
    __builtin_prefetch(&scene.positions[tri.v0]);
    __builtin_prefetch(&scene.positions[tri.v1]);
    __builtin_prefetch(&scene.positions[tri.v2]);
}

inline SurfaceHit surface_at(const Scene& scene, const Ray& ray, const Hit& hit) {
    SurfaceHit s;
    Vec3 n;
    if (scene.is_sphere(hit.prim)) {
        const Sphere& sp = scene.sphere(hit.prim);
        const Vec3 p = ray.org + ray.dir * hit.t;
        n = (p - sp.center) * (1.f / sp.radius);
        n = normalize(n);
        s.position = sp.center + n * sp.radius;  // re-project: error ~ radius, not distance
        s.position_error = sphere_point_error(sp.center, n, sp.radius);
    } else {
        const Triangle& tri = scene.triangles[hit.prim];
        const Vec3& p0 = scene.positions[tri.v0];
        const Vec3& p1 = scene.positions[tri.v1];
        const Vec3& p2 = scene.positions[tri.v2];
        const float w = 1.f - hit.u - hit.v;
        s.position = p0 * w + p1 * hit.u + p2 * hit.v;  // barycentric: error ~ vertex magnitude
        s.position_error = triangle_point_error(p0, p1, p2, w, hit.u, hit.v);
        n = normalize(cross(p1 - p0, p2 - p0));
    }
    s.front_face = dot(n, ray.dir) < 0.f;
    s.normal = s.front_face ? n : -n;
    s.material = scene.material_of(hit.prim);
    return s;
}

// The surfaces of a stream's hits (every id's hit valid), as the stream tracer computes them
// before its emission filter: the scene's arrays are read at random, so each hit's triangle is
// fetched 16 rays ahead and its vertices 8 ahead (the stream is known in advance, unlike one
// ray at a time). The surface-read microbenchmark times this same loop.
inline void compute_surfaces(const Scene& scene, const Ray* rays, const Hit* hits,
                             const uint32_t* ids, uint32_t len, SurfaceHit* surf) {
    for (uint32_t i = 0; i < len; ++i) {
        if (i + 16 < len) prefetch_surface_triangle(scene, hits[ids[i + 16]].prim);
        if (i + 8 < len) prefetch_surface_vertices(scene, hits[ids[i + 8]].prim);
        surf[ids[i]] = surface_at(scene, rays[ids[i]], hits[ids[i]]);
    }
}

// A spawned ray's origin on the side of s that n points to (s.normal: the side the incoming
// ray came from; -s.normal: through the surface).
inline Vec3 offset_ray_origin(const SurfaceHit& s, const Vec3& n) {
    return offset_ray_origin(s.position, s.position_error, n);
}

}  // namespace sfx
