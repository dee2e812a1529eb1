#pragma once
// Programmatic scenes shared by the tracer tests.

#include <vector>

#include "workloads/scene.h"

namespace sfx::test {

inline Material lambertian(Vec3 kd, Vec3 emission = Vec3(0.f)) {
    Material m;
    m.kind = MaterialKind::lambertian;
    m.diffuse = kd;
    m.emission = emission;
    return m;
}

// Box walls (triangles), an area light, a glass and a glossy sphere, a lens; the variants
// switch on ambient light, an environment, and remove the lights.
enum class Variant { lights, ambient, environment_only, emissive_sphere };

inline Scene box_scene(Variant variant) {
    Scene s;
    s.name = "box";
    s.materials = {lambertian({0.7f, 0.7f, 0.7f}), lambertian({0.7f, 0.1f, 0.1f}),
                   lambertian(Vec3(0.f), {12.f, 10.f, 8.f})};
    Material glass;
    glass.kind = MaterialKind::dielectric;
    glass.ior = 1.5f;
    Material glossy;
    glossy.kind = MaterialKind::glossy;
    glossy.diffuse = {0.2f, 0.3f, 0.6f};
    glossy.specular = Vec3(0.3f);
    glossy.exponent = 60.f;
    s.materials.push_back(glass);
    s.materials.push_back(glossy);
    auto quad = [&](Vec3 o, Vec3 u, Vec3 v, uint32_t mat) {
        const uint32_t b = uint32_t(s.positions.size());
        s.positions.insert(s.positions.end(), {o, o + u, o + u + v, o + v});
        s.triangles.push_back({b, b + 1, b + 2, mat});
        s.triangles.push_back({b, b + 2, b + 3, mat});
    };
    quad({-2, -2, -2}, {4, 0, 0}, {0, 0, 4}, 0);  // floor
    quad({-2, -2, -2}, {0, 4, 0}, {4, 0, 0}, 0);  // back
    quad({-2, -2, -2}, {0, 0, 4}, {0, 4, 0}, 1);  // left, red
    if (variant != Variant::environment_only) {
        quad({-2, 2, -2}, {0, 0, 4}, {4, 0, 0}, 0);  // ceiling
        if (variant != Variant::emissive_sphere)
            quad({-0.5f, 1.99f, -0.5f}, {1, 0, 0}, {0, 0, 1}, 2);  // light
    }
    // Small triangles on the floor, so leaves hold several primitives and shadows are fine.
    for (int i = 0; i < 40; ++i) {
        const float x = -1.8f + 0.09f * float(i), z = 1.0f - 0.05f * float(i % 7);
        const uint32_t b = uint32_t(s.positions.size());
        s.positions.insert(s.positions.end(),
                           {{x, -1.9f, z}, {x + 0.07f, -1.9f, z}, {x, -1.2f + 0.01f * i, z}});
        s.triangles.push_back({b, b + 1, b + 2, uint32_t(i % 2)});
    }
    s.spheres = {{{-0.8f, -1.2f, -0.5f}, 0.8f, 3}, {{0.9f, -1.3f, 0.3f}, 0.7f, 4}};
    if (variant == Variant::emissive_sphere) s.spheres.push_back({{0.f, 1.2f, 0.f}, 0.3f, 2});
    s.camera.eye = {0.f, 0.f, 6.f};
    s.camera.look_at = {0.f, 0.f, 0.f};
    s.camera.aperture_radius = 0.05f;
    s.camera.focal_distance = 6.f;
    s.max_depth = 4;
    if (variant == Variant::ambient) s.ambient = {0.2f, 0.25f, 0.3f};
    if (variant == Variant::environment_only) s.environment = {0.6f, 0.7f, 0.9f};
    std::vector<uint32_t> groups(s.primitive_count());
    for (uint32_t p = 0; p < groups.size(); ++p) groups[p] = p / 2;
    s.finalize(groups);
    return s;
}

}  // namespace sfx::test
