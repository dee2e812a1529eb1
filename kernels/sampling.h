#pragma once
// Warps from uniform numbers to directions and points, with their densities.

#include <cmath>

#include "base/vec.h"

namespace sfx {

constexpr float k_pi = 3.14159265358979323846f;
constexpr float k_inv_pi = 0.318309886183790671538f;

// Uniform point on the unit disk (Shirley-Chiu concentric map); z is 0.
inline Vec3 sample_concentric_disk(float u, float v) {
    const float a = 2.f * u - 1.f, b = 2.f * v - 1.f;
    if (a == 0.f && b == 0.f) return {0.f, 0.f, 0.f};
    float r, phi;
    if (std::fabs(a) > std::fabs(b)) {
        r = a;
        phi = (k_pi / 4.f) * (b / a);
    } else {
        r = b;
        phi = (k_pi / 2.f) - (k_pi / 4.f) * (a / b);
    }
    return {r * std::cos(phi), r * std::sin(phi), 0.f};
}

// Cosine-weighted direction about +z (Malley: the concentric disk lifted to the hemisphere).
inline Vec3 sample_cosine_hemisphere(float u, float v) {
    const Vec3 d = sample_concentric_disk(u, v);
    return {d.x, d.y, std::sqrt(std::max(0.f, 1.f - d.x * d.x - d.y * d.y))};
}
inline float cosine_hemisphere_pdf(float cos_theta) { return cos_theta > 0.f ? cos_theta * k_inv_pi : 0.f; }

// Uniform point on a triangle as barycentric weights (b1, b2) of p1 and p2.
inline void sample_triangle(float u, float v, float& b1, float& b2) {
    const float su = std::sqrt(u);
    b1 = v * su;
    b2 = 1.f - su;
}

// Uniform direction on the unit sphere.
inline Vec3 sample_uniform_sphere(float u, float v) {
    const float z = 1.f - 2.f * u;
    const float r = std::sqrt(std::max(0.f, 1.f - z * z));
    const float phi = 2.f * k_pi * v;
    return {r * std::cos(phi), r * std::sin(phi), z};
}

// Express a local (+z = normal) direction in world space.
inline Vec3 to_world(const Vec3& local, const Vec3& n) {
    Vec3 t, b;
    orthonormal_basis(n, t, b);
    return t * local.x + b * local.y + n * local.z;
}

}  // namespace sfx
