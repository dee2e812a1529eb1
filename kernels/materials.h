#pragma once
// Material math: Fresnel, refraction, and the coupled glossy model (a diffuse base under a
// glossy layer, Ashikhmin & Shirley 2000, isotropic). Directions point away from the surface.

#include <cmath>

#include "kernels/sampling.h"
#include "base/vec.h"

namespace sfx {

// Unpolarised Fresnel reflectance of a dielectric interface. cos_i > 0 is the cosine on the
// incident side, eta = n_transmitted / n_incident. Returns 1 under total internal reflection.
inline float fresnel_dielectric(float cos_i, float eta) {
    cos_i = std::min(1.f, std::max(0.f, cos_i));
    // cos_t = sqrt(eta^2 - 1 + cos_i^2) / eta: exact for eta = 1 (sqrt(fl(c^2)) == c), so an
    // index-matched interface reflects exactly nothing.
    const float eta2_cos2_t = eta * eta - 1.f + cos_i * cos_i;
    if (eta2_cos2_t <= 0.f) return 1.f;
    const float cos_t = std::sqrt(eta2_cos2_t) / eta;
    const float r_par = (eta * cos_i - cos_t) / (eta * cos_i + cos_t);
    const float r_perp = (cos_i - eta * cos_t) / (cos_i + eta * cos_t);
    return 0.5f * (r_par * r_par + r_perp * r_perp);
}

inline Vec3 reflect(const Vec3& wo, const Vec3& n) { return n * (2.f * dot(wo, n)) - wo; }

// Refract wo (pointing away, on the side n points to) into the other side. eta as above.
// Returns false under total internal reflection.
inline bool refract(const Vec3& wo, const Vec3& n, float eta, Vec3& wt) {
    const float cos_i = dot(n, wo);
    const float sin2_t = std::max(0.f, 1.f - cos_i * cos_i) / (eta * eta);
    if (sin2_t >= 1.f) return false;
    const float cos_t = std::sqrt(1.f - sin2_t);
    wt = -wo * (1.f / eta) + n * (cos_i / eta - cos_t);
    return true;
}

inline Vec3 schlick(const Vec3& rs, float cos_theta) {
    const float m = 1.f - cos_theta;
    const float m5 = (m * m) * (m * m) * m;
    return rs + (Vec3(1.f) - rs) * m5;
}

// Ashikhmin-Shirley BRDF value (times nothing: no cosine). n is the shading normal.
inline Vec3 glossy_eval(const Vec3& diffuse, const Vec3& specular, float exponent,
                        const Vec3& n, const Vec3& wo, const Vec3& wi) {
    const float cos_o = dot(n, wo), cos_i = dot(n, wi);
    if (cos_o <= 0.f || cos_i <= 0.f) return Vec3(0.f);
    Vec3 h = normalize(wo + wi);
    const float cos_h = std::max(0.f, dot(n, h));
    const float ho = dot(h, wo);
    const float spec_norm = (exponent + 1.f) / (8.f * k_pi);
    const float d = spec_norm * std::pow(cos_h, exponent) / (ho * std::max(cos_i, cos_o));
    const Vec3 f_spec = schlick(specular, ho) * d;
    auto p5 = [](float c) { const float m = 1.f - 0.5f * c; return (m * m) * (m * m) * m; };
    const float diff_norm = 28.f / (23.f * k_pi) * (1.f - p5(cos_i)) * (1.f - p5(cos_o));
    const Vec3 f_diff = diffuse * (Vec3(1.f) - specular) * diff_norm;
    return f_spec + f_diff;
}

// Density of the half-vector lobe (pdf of wi): (n+1)/(2 pi) cos_h^n / (4 (wo.h)).
inline float glossy_spec_pdf(float exponent, const Vec3& n, const Vec3& wo, const Vec3& wi) {
    const Vec3 h = normalize(wo + wi);
    const float cos_h = dot(n, h), ho = dot(h, wo);
    if (cos_h <= 0.f || ho <= 0.f) return 0.f;
    return (exponent + 1.f) / (2.f * k_pi) * std::pow(cos_h, exponent) / (4.f * ho);
}

// Sample a half vector about n with density proportional to cos^exponent, and reflect.
inline Vec3 glossy_sample_spec(float exponent, const Vec3& n, const Vec3& wo, float u, float v) {
    const float cos_h = std::pow(1.f - u, 1.f / (exponent + 1.f));
    const float sin_h = std::sqrt(std::max(0.f, 1.f - cos_h * cos_h));
    const float phi = 2.f * k_pi * v;
    const Vec3 h = to_world({sin_h * std::cos(phi), sin_h * std::sin(phi), cos_h}, n);
    return reflect(wo, h);
}

// The coupled model's sampling: the glossy lobe or the cosine lobe, each with probability 1/2.
// Returns the direction; its density is glossy_pdf (the mixture), so f cos / pdf is unbiased.
inline Vec3 glossy_sample(float exponent, const Vec3& n, const Vec3& wo, float u_lobe, float u,
                          float v) {
    return u_lobe < 0.5f ? glossy_sample_spec(exponent, n, wo, u, v)
                         : to_world(sample_cosine_hemisphere(u, v), n);
}

inline float glossy_pdf(float exponent, const Vec3& n, const Vec3& wo, const Vec3& wi) {
    return 0.5f * glossy_spec_pdf(exponent, n, wo, wi) + 0.5f * cosine_hemisphere_pdf(dot(n, wi));
}

}  // namespace sfx
