#include "workloads/scene.h"

#include <cmath>
#include <map>
#include <sstream>
#include <stdexcept>

#include "base/hash.h"

namespace sfx {

const char* to_string(MaterialKind kind) {
    switch (kind) {
        case MaterialKind::lambertian:
            return "lambertian";
        case MaterialKind::dielectric:
            return "dielectric";
        case MaterialKind::glossy:
            return "glossy";
    }
    return "?";
}

bool FeatureSet::*FeatureSet::material_flag(MaterialKind kind) {
    switch (kind) {
        case MaterialKind::lambertian:
            return &FeatureSet::lambertian;
        case MaterialKind::dielectric:
            return &FeatureSet::dielectric;
        case MaterialKind::glossy:
            return &FeatureSet::glossy;
    }
    throw std::logic_error("FeatureSet::material_flag: not a material kind");
}

uint32_t FeatureSet::material_kinds() const {
    uint32_t n = 0;
    for (MaterialKind k : k_material_kinds) n += uses(k);
    return n;
}

std::string FeatureSet::describe() const {
    std::ostringstream s;
    const char* sep = "";
    auto item = [&](bool on, const char* name) {
        if (on) {
            s << sep << name;
            sep = ", ";
        }
    };
    item(triangles, "triangles");
    item(spheres, "spheres");
    for (MaterialKind k : k_material_kinds) item(uses(k), to_string(k));
    item(thin_lens, "thin-lens");
    item(ambient, "ambient");
    item(environment, "environment");
    s << sep << light_count << " light" << (light_count == 1 ? "" : "s") << ", depth " << max_depth;
    return s.str();
}

float Scene::primitive_area(uint32_t prim) const {
    if (is_sphere(prim)) {
        const float r = sphere(prim).radius;
        return 4.f * float(M_PI) * r * r;
    }
    const Triangle& t = triangles[prim];
    return 0.5f *
           length(cross(positions[t.v1] - positions[t.v0], positions[t.v2] - positions[t.v0]));
}

Bounds3 Scene::primitive_bounds(uint32_t prim) const {
    Bounds3 b;
    if (is_sphere(prim)) {
        const Sphere& s = sphere(prim);
        b.extend(s.center - Vec3(s.radius));
        b.extend(s.center + Vec3(s.radius));
    } else {
        const Triangle& t = triangles[prim];
        b.extend(positions[t.v0]);
        b.extend(positions[t.v1]);
        b.extend(positions[t.v2]);
    }
    return b;
}

Bounds3 Scene::bounds() const {
    Bounds3 b;
    for (uint32_t p = 0; p < primitive_count(); ++p) b.extend(primitive_bounds(p));
    return b;
}

FeatureSet Scene::features() const {
    FeatureSet f;
    f.triangles = !triangles.empty();
    f.spheres = !spheres.empty();
    std::vector<bool> used(materials.size(), false);
    for (const Triangle& t : triangles) used[t.material] = true;
    for (const Sphere& s : spheres) used[s.material] = true;
    for (size_t m = 0; m < materials.size(); ++m) {
        if (used[m]) f.*FeatureSet::material_flag(materials[m].kind) = true;
    }
    f.thin_lens = camera.aperture_radius > 0.f;
    f.ambient = !is_black(ambient);
    f.environment = !is_black(environment);
    f.light_count = uint32_t(lights.size());
    for (const AreaLight& light : lights) {
        float sphere_area = 0.f;
        for (const uint32_t p : light.primitives)
            if (is_sphere(p)) sphere_area += primitive_area(p);
        if (light.area > 0.f)
            f.sphere_light_share += sphere_area / light.area / float(lights.size());
    }
    double sphere_area = 0.0, area = 0.0;
    for (uint32_t p = 0; p < primitive_count(); ++p) {
        const double a = primitive_area(p);
        area += a;
        if (is_sphere(p)) sphere_area += a;
    }
    if (area > 0.0) f.sphere_area_share = float(sphere_area / area);
    f.max_depth = max_depth;
    return f;
}

void Scene::finalize(const std::vector<uint32_t>& light_groups) {
    lights.clear();
    std::map<uint32_t, size_t> light_of_group;
    for (uint32_t p = 0; p < primitive_count(); ++p) {
        const Material& m = materials[material_of(p)];
        if (!m.emissive()) continue;
        const float a = primitive_area(p);
        if (!(a > 0.f)) continue;  // degenerate emitters can be neither hit nor sampled
        size_t index;
        if (light_groups.empty()) {
            index = lights.size();
            lights.emplace_back();
        } else {
            auto [it, inserted] = light_of_group.emplace(light_groups[p], lights.size());
            if (inserted) lights.emplace_back();
            index = it->second;
        }
        AreaLight& light = lights[index];
        light.primitives.push_back(p);
        light.area += a;
        light.area_cdf.push_back(light.area);
        light.emission = m.emission;
    }
}

uint64_t Scene::geometry_bytes() const {
    return positions.size() * sizeof(Vec3) + triangles.size() * sizeof(Triangle) +
           spheres.size() * sizeof(Sphere) + materials.size() * sizeof(Material);
}

// FNV-1a over the bytes that decide a trace; kept one structure a line, as a checklist.
// clang-format off
namespace {
struct Fnv : Fnv1a {
    void f(float v) { bytes(&v, 4); }
    void u(uint32_t v) { bytes(&v, 4); }
    void v3(const Vec3& v) { f(v.x); f(v.y); f(v.z); }
};
}  // namespace

uint64_t scene_hash(const Scene& s) {
    Fnv h;
    h.u(uint32_t(s.positions.size()));
    for (const Vec3& p : s.positions) h.v3(p);
    h.u(uint32_t(s.triangles.size()));
    for (const Triangle& t : s.triangles) { h.u(t.v0); h.u(t.v1); h.u(t.v2); h.u(t.material); }
    h.u(uint32_t(s.spheres.size()));
    for (const Sphere& sp : s.spheres) { h.v3(sp.center); h.f(sp.radius); h.u(sp.material); }
    h.u(uint32_t(s.materials.size()));
    for (const Material& m : s.materials) {
        h.u(uint32_t(m.kind));
        h.v3(m.diffuse); h.v3(m.specular); h.f(m.exponent); h.f(m.ior);
        h.v3(m.transmission); h.v3(m.emission);
    }
    h.u(uint32_t(s.lights.size()));
    for (const AreaLight& l : s.lights) {
        h.u(uint32_t(l.primitives.size()));
        for (uint32_t p : l.primitives) h.u(p);
    }
    const ThinLensCamera& c = s.camera;
    h.v3(c.eye); h.v3(c.look_at); h.v3(c.up);
    h.f(c.vertical_fov_degrees); h.f(c.aperture_radius); h.f(c.focal_distance);
    h.v3(s.ambient); h.v3(s.environment); h.u(s.max_depth);
    return h.h;
}
// clang-format on

}  // namespace sfx
