#pragma once
// The path tracer's per-ray steps, shared by the reference (depth-first) and the stream
// (breadth-first) tracers. Each step is a pure function of the path's state, its ray and its
// hit, so calling the same steps in the same order per path gives the same bits in both.
//
// Estimator: a path carries exactly one ray at a time. At a Lambertian hit it samples either
// direct light (a shadow ray, then the path ends) or indirect light (a cosine bounce, after
// which hitting an emitter counts nothing, since direct sampling covers emitters), chosen with
// probability 1/2 each and weighted by the inverse. Dielectric and glossy bounces count the
// emission they hit. With a constant ambient term, Lambertian hits add kd * ambient and never
// bounce (the paper's rtrt configuration). This is the stream paper's Fig. 4 filter stack.

#include "kernels/intersect.h"
#include "kernels/lights.h"
#include "kernels/materials.h"
#include "kernels/rng.h"
#include "workloads/scene.h"

namespace sfx {

enum class RayKind : uint8_t { camera, extension, shadow };

struct PathState {
    PathKey key;
    Vec3 throughput{1.f};
    Vec3 radiance{0.f};
    Vec3 pending{0.f};    // what the shadow ray adds if nothing blocks it
    uint32_t bounce = 0;  // generation of the current ray; 0 is the camera ray
    RayKind kind = RayKind::camera;
    bool count_emission = true;  // false right after a Lambertian indirect bounce
};

// Shadow ray resolved: the path ends.
inline void finish_shadow(PathState& p, bool occluded) {
    if (!occluded) p.radiance += p.pending;
}

// Ray left the scene: the path ends. The environment is never light-sampled, so it counts.
inline void shade_miss(PathState& p, const Scene& scene) {
    p.radiance += p.throughput * scene.environment;
}

// Ray hit an emitter ("light hit" filter). Emitters also reflect, so the path goes on.
inline void shade_emission(PathState& p, const Material& m) {
    if (p.count_emission && m.emissive()) p.radiance += p.throughput * m.emission;
}

inline bool may_scatter(const PathState& p, uint32_t max_depth) { return p.bounce < max_depth; }

// Probability that a Lambertian hit samples direct light.
inline float lambertian_direct_probability(const Scene& scene) {
    if (scene.lights.empty()) return 0.f;
    return is_black(scene.ambient) ? 0.5f : 1.f;
}

inline bool lambertian_takes_direct(const PathState& p, const Scene& scene) {
    return p.key.uniform(p.bounce + 1, RngDim::lobe_choice) < lambertian_direct_probability(scene);
}

inline void add_ambient(PathState& p, const Material& m, const Scene& scene) {
    p.radiance += p.throughput * m.diffuse * scene.ambient;
}

inline void begin_next(PathState& p, RayKind kind) {
    p.bounce += 1;
    p.kind = kind;
}

// Direct light: one shadow ray to a point on a light. Returns false when nothing is to trace.
inline bool lambertian_direct(PathState& p, const Scene& scene, const Material& m,
                              const SurfaceHit& s, Ray& next) {
    const uint32_t b = p.bounce + 1;
    const LightSample ls = sample_light(scene, p.key.uniform(b, RngDim::light_choice),
                                        p.key.uniform(b, RngDim::light_w),
                                        p.key.uniform(b, RngDim::light_u),
                                        p.key.uniform(b, RngDim::light_v));
    const Vec3 to_light = ls.position - s.position;
    const float dist2 = dot(to_light, to_light);
    if (!(dist2 > 0.f)) return false;
    const Vec3 wi = to_light * (1.f / std::sqrt(dist2));
    const float cos_s = dot(s.normal, wi);
    const float cos_l = std::fabs(dot(ls.normal, wi));  // emitters are two-sided
    if (!(cos_s > 0.f) || !(cos_l > 0.f)) return false;
    const float q = lambertian_direct_probability(scene);
    const float weight = k_inv_pi * cos_s * cos_l / (dist2 * ls.pdf_area * q);
    p.pending = p.throughput * m.diffuse * ls.emission * weight;
    const Vec3 light_side = dot(ls.normal, wi) < 0.f ? ls.normal : -ls.normal;
    const Vec3 from = offset_ray_origin(s, s.normal);
    const Vec3 to = offset_ray_origin(ls.position, ls.position_error, light_side);
    next.org = from;
    next.dir = to - from;
    next.t_max = 1.f;
    begin_next(p, RayKind::shadow);
    return true;
}

// Indirect light: a cosine-weighted bounce; kd / (1 - q) is exactly f cos / pdf / (1 - q).
inline bool lambertian_indirect(PathState& p, const Scene& scene, const Material& m,
                                const SurfaceHit& s, Ray& next) {
    const uint32_t b = p.bounce + 1;
    const Vec3 local = sample_cosine_hemisphere(p.key.uniform(b, RngDim::direction_u),
                                                p.key.uniform(b, RngDim::direction_v));
    if (!(local.z > 0.f)) return false;
    const float q = lambertian_direct_probability(scene);
    p.throughput *= m.diffuse * (1.f / (1.f - q));
    if (is_black(p.throughput)) return false;
    p.count_emission = false;
    next.org = offset_ray_origin(s, s.normal);
    next.dir = to_world(local, s.normal);
    next.t_max = INFINITY;
    begin_next(p, RayKind::extension);
    return true;
}

// Dielectric: reflect with probability F, else refract; the weight is exactly 1 (times tint).
inline bool dielectric_scatter(PathState& p, const Material& m, const SurfaceHit& s,
                               const Ray& ray, Ray& next) {
    const uint32_t b = p.bounce + 1;
    const Vec3 wo = -normalize(ray.dir);
    const float eta = s.front_face ? m.ior : 1.f / m.ior;
    const float cos_i = dot(s.normal, wo);
    const float f = fresnel_dielectric(cos_i, eta);
    Vec3 wt;
    if (p.key.uniform(b, RngDim::lobe_choice) < f || !refract(wo, s.normal, eta, wt)) {
        next.dir = reflect(wo, s.normal);
        next.org = offset_ray_origin(s, s.normal);
    } else {
        p.throughput *= m.transmission;
        next.dir = wt;
        next.org = offset_ray_origin(s, -s.normal);
    }
    p.count_emission = true;
    next.t_max = INFINITY;
    begin_next(p, RayKind::extension);
    return !is_black(p.throughput);
}

// Coupled glossy: one of the two lobes chosen with probability 1/2, weighted by the mixture pdf.
inline bool glossy_scatter(PathState& p, const Material& m, const SurfaceHit& s, const Ray& ray,
                           Ray& next) {
    const uint32_t b = p.bounce + 1;
    const Vec3 wo = -normalize(ray.dir);
    const float u = p.key.uniform(b, RngDim::direction_u);
    const float v = p.key.uniform(b, RngDim::direction_v);
    const Vec3 wi =
        glossy_sample(m.exponent, s.normal, wo, p.key.uniform(b, RngDim::lobe_choice), u, v);
    const float cos_i = dot(s.normal, wi);
    if (!(cos_i > 0.f)) return false;
    const float pdf = glossy_pdf(m.exponent, s.normal, wo, wi);
    if (!(pdf > 0.f)) return false;
    const Vec3 f = glossy_eval(m.diffuse, m.specular, m.exponent, s.normal, wo, wi);
    p.throughput *= f * (cos_i / pdf);
    if (is_black(p.throughput)) return false;
    p.count_emission = true;
    next.org = offset_ray_origin(s, s.normal);
    next.dir = wi;
    next.t_max = INFINITY;
    begin_next(p, RayKind::extension);
    return true;
}

// The whole filter stack for one non-shadow ray, in the stream tracer's stage order.
// Returns true with `next` filled when the path continues.
inline bool shade(PathState& p, const Scene& scene, uint32_t max_depth, const Ray& ray,
                  const Hit& hit, Ray& next) {
    if (!hit.valid()) {
        shade_miss(p, scene);
        return false;
    }
    const SurfaceHit s = surface_at(scene, ray, hit);
    const Material& m = scene.materials[s.material];
    shade_emission(p, m);
    if (!may_scatter(p, max_depth)) return false;
    switch (m.kind) {
        case MaterialKind::lambertian:
            if (!is_black(scene.ambient)) add_ambient(p, m, scene);
            if (lambertian_takes_direct(p, scene)) return lambertian_direct(p, scene, m, s, next);
            if (!is_black(scene.ambient)) return false;
            return lambertian_indirect(p, scene, m, s, next);
        case MaterialKind::dielectric: return dielectric_scatter(p, m, s, ray, next);
        case MaterialKind::glossy: return glossy_scatter(p, m, s, ray, next);
    }
    return false;
}

}  // namespace sfx
