#pragma once
// Helpers shared by the geometry tests: a seeded generator whose numbers do not depend on the
// standard library's distributions, ulp comparisons, mesh builders, and a scene+BVH bundle.

#include <cmath>
#include <cstdint>
#include <cstring>
#include <memory>
#include <random>
#include <utility>
#include <vector>

#include "kernels/bvh.h"
#include "kernels/intersect.h"
#include "workloads/scene.h"

namespace sfx::test {

// Deterministic uniform numbers from mt19937's raw output (its sequence is fixed by the standard).
class TestRng {
  public:
    explicit TestRng(uint32_t seed) : m_engine(seed) {}
    float uniform() { return float(m_engine() >> 8) * (1.f / 16777216.f); }  // [0, 1)
    double uniform_double() { return double(m_engine() >> 5) * (1.0 / 134217728.0); }
    float range(float lo, float hi) { return lo + (hi - lo) * uniform(); }
    uint32_t below(uint32_t n) { return uint32_t(m_engine() % n); }
    Vec3 unit_vector() {  // uniform on the sphere
        const float z = 1.f - 2.f * uniform();
        const float r = std::sqrt(std::max(0.f, 1.f - z * z));
        const float phi = 6.2831853f * uniform();
        return {r * std::cos(phi), r * std::sin(phi), z};
    }
    // Uniform direction in the hemisphere around unit n with cos(angle to n) >= min_cos.
    Vec3 hemisphere(const Vec3& n, float min_cos) {
        for (;;) {
            const Vec3 d = unit_vector();
            const float c = dot(d, n);
            if (c >= min_cos) return d;
            if (-c >= min_cos) return -d;
        }
    }

  private:
    std::mt19937 m_engine;
};

// Distance in representable floats (monotonic integer mapping of the bit patterns).
inline int64_t ulp_distance(float a, float b) {
    auto key = [](float f) {
        int32_t i;
        std::memcpy(&i, &f, 4);
        return i < 0 ? int64_t(INT32_MIN) - int64_t(i) : int64_t(i);
    };
    const int64_t d = key(a) - key(b);
    return d < 0 ? -d : d;
}
inline bool within_ulps(float a, float b, int64_t ulps = 16) {
    return ulp_distance(a, b) <= ulps;
}
inline bool same_bits(float a, float b) {
    return float_bits(a) == float_bits(b);
}

inline uint32_t add_material(Scene& s) {
    Material m;
    m.name = "grey";
    s.materials.push_back(m);
    return uint32_t(s.materials.size() - 1);
}

inline uint32_t add_vertex(Scene& s, const Vec3& p) {
    s.positions.push_back(p);
    return uint32_t(s.positions.size() - 1);
}

inline void add_triangle(Scene& s, uint32_t a, uint32_t b, uint32_t c) {
    s.triangles.push_back({a, b, c, 0});
}

inline void add_triangle(Scene& s, const Vec3& a, const Vec3& b, const Vec3& c) {
    const uint32_t i = add_vertex(s, a), j = add_vertex(s, b), k = add_vertex(s, c);
    add_triangle(s, i, j, k);
}

// Closed UV sphere: `segments` around the axis, segments / 2 bands, one vertex per pole,
// every edge shared by exactly two triangles. Positions are computed in double and rounded
// once; `quantum` > 0 additionally snaps the offsets from the center to a grid.
inline void add_sphere_mesh(Scene& s, const Vec3& center, double radius, int segments,
                            double quantum = 0.0) {
    const int bands = segments / 2;
    auto put = [&](double x, double y, double z) {
        if (quantum > 0.0) {
            x = std::round(x / quantum) * quantum;
            y = std::round(y / quantum) * quantum;
            z = std::round(z / quantum) * quantum;
        }
        return add_vertex(s, Vec3(float(double(center.x) + x), float(double(center.y) + y),
                                  float(double(center.z) + z)));
    };
    const uint32_t north = put(0, 0, radius);
    const uint32_t first_ring = uint32_t(s.positions.size());
    for (int b = 1; b < bands; ++b) {
        const double theta = M_PI * b / bands;
        for (int i = 0; i < segments; ++i) {
            const double phi = 2.0 * M_PI * i / segments;
            put(radius * std::sin(theta) * std::cos(phi), radius * std::sin(theta) * std::sin(phi),
                radius * std::cos(theta));
        }
    }
    const uint32_t south = put(0, 0, -radius);
    auto ring = [&](int b, int i) {
        return first_ring + uint32_t((b - 1) * segments + i % segments);
    };
    for (int i = 0; i < segments; ++i) add_triangle(s, north, ring(1, i), ring(1, i + 1));
    for (int b = 1; b + 1 < bands; ++b)
        for (int i = 0; i < segments; ++i) {
            add_triangle(s, ring(b, i), ring(b + 1, i), ring(b + 1, i + 1));
            add_triangle(s, ring(b, i), ring(b + 1, i + 1), ring(b, i + 1));
        }
    for (int i = 0; i < segments; ++i)
        add_triangle(s, ring(bands - 1, i), south, ring(bands - 1, i + 1));
}

// A scene and its BVH, kept together (the BVH points at the scene, so neither may move).
struct World {
    Scene scene;
    Bvh bvh;
    explicit World(Scene s, const BvhBuildOptions& options = {})
        : scene(std::move(s)), bvh(scene, options) {}
    World(const World&) = delete;
    World& operator=(const World&) = delete;
};

inline std::unique_ptr<World> make_world(Scene s, const BvhBuildOptions& options = {}) {
    if (s.materials.empty()) add_material(s);
    s.finalize();
    return std::make_unique<World>(std::move(s), options);
}

// Closest hit by testing every primitive with the ray's own t_max: independent of any order.
inline Hit brute_force(const Bvh& bvh, const Ray& ray) {
    Hit hit;
    if (!ray_is_valid(ray)) return hit;
    const RayPrecomp r(ray);
    for (uint32_t p = 0; p < bvh.scene().primitive_count(); ++p)
        bvh.intersect_primitive(r, p, ray.t_max, hit);
    return hit;
}

inline bool brute_force_occluded(const Bvh& bvh, const Ray& ray) {
    return brute_force(bvh, ray).valid();
}

}  // namespace sfx::test
