#pragma once
// Area-light sampling: choose a light uniformly, a primitive of it by area, a point uniformly
// on that primitive. The density per unit area is therefore 1 / (light_count * light_area).

#include <algorithm>

#include "kernels/intersect.h"
#include "kernels/sampling.h"
#include "workloads/scene.h"

namespace sfx {

struct LightSample {
    Vec3 position;
    Vec3 position_error;  // bound on |position - true surface point|, per component
    Vec3 normal;  // outward geometric normal of the sampled primitive
    Vec3 emission;
    float pdf_area = 0.f;  // density per unit area of choosing this point
    uint32_t light = 0;
    uint32_t prim = 0;
};

inline float light_pdf_area(const Scene& scene, uint32_t light) {
    return 1.f / (float(scene.lights.size()) * scene.lights[light].area);
}

// u_light picks the light and (by rescaling) the primitive; (u, v) pick the point.
inline LightSample sample_light(const Scene& scene, float u_light, float u_prim, float u,
                                float v) {
    LightSample s;
    const uint32_t n = uint32_t(scene.lights.size());
    s.light = std::min(n - 1, uint32_t(u_light * float(n)));
    const AreaLight& light = scene.lights[s.light];
    const float target = u_prim * light.area;
    const size_t i = std::min(light.primitives.size() - 1,
                              size_t(std::upper_bound(light.area_cdf.begin(), light.area_cdf.end(),
                                                      target) -
                                     light.area_cdf.begin()));
    s.prim = light.primitives[i];
    if (scene.is_sphere(s.prim)) {
        const Sphere& sp = scene.sphere(s.prim);
        s.normal = sample_uniform_sphere(u, v);
        s.position = sp.center + s.normal * sp.radius;
        s.position_error = sphere_point_error(sp.center, s.normal, sp.radius);
    } else {
        const Triangle& t = scene.triangles[s.prim];
        const Vec3& p0 = scene.positions[t.v0];
        const Vec3& p1 = scene.positions[t.v1];
        const Vec3& p2 = scene.positions[t.v2];
        float b1, b2;
        sample_triangle(u, v, b1, b2);
        const float b0 = 1.f - b1 - b2;
        s.position = p0 * b0 + p1 * b1 + p2 * b2;
        s.position_error = triangle_point_error(p0, p1, p2, b0, b1, b2);
        s.normal = normalize(cross(p1 - p0, p2 - p0));
    }
    s.emission = light.emission;
    s.pdf_area = light_pdf_area(scene, s.light);
    return s;
}

}  // namespace sfx
