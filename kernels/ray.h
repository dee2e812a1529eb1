#pragma once
// Rays and hit records shared by every tracer and by the Embree cross-check.

#include <cstdint>
#include <limits>

#include "base/vec.h"

namespace sfx {

constexpr uint32_t k_no_hit = std::numeric_limits<uint32_t>::max();

struct Ray {
    Vec3 org;
    Vec3 dir;
    float t_max = INFINITY;  // the ray covers (0, t_max); origins are already offset off surfaces
};

// A ray is traced only if all of its numbers are finite and its direction is nonzero;
// anything else is inactive: it misses without touching the BVH. Denormal direction
// components count as zero (RayPrecomp flushes them), so an all-denormal direction is zero.
inline bool ray_is_valid(const Ray& r) {
    return is_finite(r.org) && is_finite(r.dir) && !std::isnan(r.t_max) && r.t_max > 0.f &&
           max_component(abs(r.dir)) >= std::numeric_limits<float>::min();
}

struct Hit {
    float t = INFINITY;
    float u = 0.f, v = 0.f;  // barycentrics of v1 and v2 for triangles; unused for spheres
    uint32_t prim = k_no_hit;

    bool valid() const { return prim != k_no_hit; }
};

// Closest hit with deterministic ties: equal t goes to the lower primitive id. Always inlined:
// the wide stream kernels call it (kernels/simd/lanes.h says why nothing shared may be emitted
// out of line there).
inline __attribute__((always_inline)) bool closer(float t, uint32_t prim, const Hit& best) {
    return t < best.t || (t == best.t && prim < best.prim);
}

}  // namespace sfx
