#pragma once
// Robust ray/box, ray/triangle and ray/sphere tests, written once and called by every tracer.
// - Boxes: conservative slab test (Ize, "Robust BVH Ray Traversal", JCGT 2013).
// - Triangles: watertight test (Woop, Benthin, Wald, JCGT 2013): no ray slips between
//   triangles sharing an edge or vertex.
// - Spheres: the numerically careful quadratic of Haines et al. (Ray Tracing Gems, ch. 7).
// - Spawned rays: origins pushed off surfaces (Waechter & Binder, Ray Tracing Gems, ch. 6).

#include <cfloat>
#include <cmath>
#include <cstring>

#include "kernels/ray.h"
#include "workloads/scene.h"

namespace sfx {

// Per-ray constants of the watertight triangle test and the slab test.
struct RayPrecomp {
    Vec3 org;
    Vec3 dir;      // denormal components flushed to (signed) zero
    Vec3 inv_dir;  // may hold +-inf; the slab test is written for that
    int kx = 0, ky = 1, kz = 2;
    float sx = 0.f, sy = 0.f, sz = 0.f;

    explicit RayPrecomp(const Ray& r) : org(r.org) {
        for (int a = 0; a < 3; ++a) {
            const float d = r.dir[a];
            dir[a] = std::fabs(d) < FLT_MIN ? std::copysign(0.f, d) : d;
            inv_dir[a] = 1.f / dir[a];
        }
        kz = max_axis(abs(dir));
        kx = kz + 1 == 3 ? 0 : kz + 1;
        ky = kx + 1 == 3 ? 0 : kx + 1;
        if (dir[kz] < 0.f) std::swap(kx, ky);  // keep the winding of the triangle test
        sx = dir[kx] / dir[kz];
        sy = dir[ky] / dir[kz];
        sz = 1.f / dir[kz];
    }
};

// gamma(n) of Higham/pbrt: bound on n roundings.
constexpr float gamma_bound(int n) {
    return (float(n) * (FLT_EPSILON * 0.5f)) / (1.f - float(n) * (FLT_EPSILON * 0.5f));
}

// Slab test over (0, t_max]. Returns the entry distance, or INFINITY on a miss.
// An axis whose direction is zero and whose origin lies on a slab plane gives 0*inf = NaN;
// the comparisons below ignore a NaN bound, which is conservative (the box is kept).
inline float intersect_box(const RayPrecomp& r, const Bounds3& b, float t_max) {
    float t0 = 0.f, t1 = t_max;
    for (int a = 0; a < 3; ++a) {
        float t_near = (b.lo[a] - r.org[a]) * r.inv_dir[a];
        float t_far = (b.hi[a] - r.org[a]) * r.inv_dir[a];
        if (t_near > t_far) std::swap(t_near, t_far);
        t_far *= 1.f + 2.f * gamma_bound(3);  // Ize: round the far bound outwards
        t0 = t_near > t0 ? t_near : t0;
        t1 = t_far < t1 ? t_far : t1;
        if (t0 > t1) return INFINITY;
    }
    return t0;
}

// Watertight ray/triangle test. On a hit with 0 < t <= t_max fills t, u, v and returns true.
// Degenerate (zero-area) triangles never hit: their determinant is zero.
inline bool intersect_triangle(const RayPrecomp& r, const Vec3& p0, const Vec3& p1,
                               const Vec3& p2, float t_max, float& t_out, float& u_out,
                               float& v_out) {
    const Vec3 a = p0 - r.org, b = p1 - r.org, c = p2 - r.org;
    const float ax = a[r.kx] - r.sx * a[r.kz], ay = a[r.ky] - r.sy * a[r.kz];
    const float bx = b[r.kx] - r.sx * b[r.kz], by = b[r.ky] - r.sy * b[r.kz];
    const float cx = c[r.kx] - r.sx * c[r.kz], cy = c[r.ky] - r.sy * c[r.kz];
    float u = cx * by - cy * bx;
    float v = ax * cy - ay * cx;
    float w = bx * ay - by * ax;
    if (u == 0.f || v == 0.f || w == 0.f) {  // on an edge: decide in double, as the paper does
        u = float(double(cx) * double(by) - double(cy) * double(bx));
        v = float(double(ax) * double(cy) - double(ay) * double(cx));
        w = float(double(bx) * double(ay) - double(by) * double(ax));
    }
    if ((u < 0.f || v < 0.f || w < 0.f) && (u > 0.f || v > 0.f || w > 0.f)) return false;
    const float det = u + v + w;
    if (det == 0.f || !std::isfinite(det)) return false;
    const float az = r.sz * a[r.kz], bz = r.sz * b[r.kz], cz = r.sz * c[r.kz];
    const float t_scaled = u * az + v * bz + w * cz;
    // Sign-agnostic range test on t * det, avoiding the division for most misses.
    if (det < 0.f ? (t_scaled >= 0.f || t_scaled < t_max * det)
                  : (t_scaled <= 0.f || t_scaled > t_max * det))
        return false;
    const float inv_det = 1.f / det;
    const float t = t_scaled * inv_det;
    if (!(t > 0.f && t <= t_max)) return false;
    t_out = t;
    u_out = v * inv_det;  // weight of p1
    v_out = w * inv_det;  // weight of p2
    return true;
}

// Ray/sphere test over (0, t_max]; returns the nearest root in range.
inline bool intersect_sphere(const RayPrecomp& r, const Sphere& s, float t_max, float& t_out) {
    const Vec3 f = r.org - s.center;
    const float a = dot(r.dir, r.dir);
    const float b_half = -dot(f, r.dir);  // -b/2
    // Discriminant from the distance of the ray's closest approach (Haines et al. eq. 7.5).
    const Vec3 l = f + r.dir * (b_half / a);
    const float r2 = s.radius * s.radius;
    const float disc = a * (r2 - dot(l, l));
    if (!(disc >= 0.f)) return false;
    const float q = b_half + std::copysign(std::sqrt(disc), b_half);
    const float c = dot(f, f) - r2;
    float t0 = c / q, t1 = q / a;  // stable pair of roots
    if (q == 0.f) t0 = t1 = 0.f;
    if (t0 > t1) std::swap(t0, t1);
    if (t0 > 0.f && t0 <= t_max) { t_out = t0; return true; }
    if (t1 > 0.f && t1 <= t_max) { t_out = t1; return true; }
    return false;
}

inline uint32_t float_bits(float f) { uint32_t i; std::memcpy(&i, &f, 4); return i; }
inline float bits_float(uint32_t i) { float f; std::memcpy(&f, &i, 4); return f; }

// Waechter & Binder: move p off the surface along n (the side the new ray leaves from),
// by a fixed number of ulps far from the origin and by a fixed distance near it.
inline Vec3 offset_ray_origin(const Vec3& p, const Vec3& n) {
    constexpr float k_origin = 1.f / 32.f, k_float_scale = 1.f / 65536.f, k_int_scale = 256.f;
    Vec3 out;
    for (int a = 0; a < 3; ++a) {
        const int of = int(k_int_scale * n[a]);
        const float pi = bits_float(uint32_t(int32_t(float_bits(p[a])) + (p[a] < 0.f ? -of : of)));
        out[a] = std::fabs(p[a]) < k_origin ? p[a] + k_float_scale * n[a] : pi;
    }
    return out;
}

// Surface data at a hit, computed the same way by every tracer.
struct SurfaceHit {
    Vec3 position;
    Vec3 normal;  // geometric, unit length, facing against the incoming ray
    bool front_face = true;  // the ray arrived from the side the stored normal points to
    uint32_t material = 0;
};

inline SurfaceHit surface_at(const Scene& scene, const Ray& ray, const Hit& hit) {
    SurfaceHit s;
    Vec3 n;
    if (scene.is_sphere(hit.prim)) {
        const Sphere& sp = scene.sphere(hit.prim);
        const Vec3 p = ray.org + ray.dir * hit.t;
        n = (p - sp.center) * (1.f / sp.radius);
        n = normalize(n);
        s.position = sp.center + n * sp.radius;  // re-project: error ~ radius, not distance
    } else {
        const Triangle& tri = scene.triangles[hit.prim];
        const Vec3& p0 = scene.positions[tri.v0];
        const Vec3& p1 = scene.positions[tri.v1];
        const Vec3& p2 = scene.positions[tri.v2];
        const float w = 1.f - hit.u - hit.v;
        s.position = p0 * w + p1 * hit.u + p2 * hit.v;  // barycentric: error ~ vertex magnitude
        n = normalize(cross(p1 - p0, p2 - p0));
    }
    s.front_face = dot(n, ray.dir) < 0.f;
    s.normal = s.front_face ? n : -n;
    s.material = scene.material_of(hit.prim);
    return s;
}

}  // namespace sfx
