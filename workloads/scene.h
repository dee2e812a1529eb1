#pragma once
// The scene model: what a workload is made of, independent of how it is traced.
// Primitive ids are global: triangles first [0, triangle_count), then spheres.
// Closest-hit ties go to the lower id, so this numbering is part of the image.

#include <cstdint>
#include <iterator>
#include <string>
#include <vector>

#include "base/huge_pages.h"
#include "base/vec.h"

namespace sfx {

enum class MaterialKind : uint8_t { lambertian, dielectric, glossy };
// Every kind, in enum order: loops over kinds (names, counts, feature flags) read this list.
inline constexpr MaterialKind k_material_kinds[] = {MaterialKind::lambertian,
                                                    MaterialKind::dielectric, MaterialKind::glossy};
inline constexpr uint32_t k_material_kind_count = uint32_t(std::size(k_material_kinds));
const char* to_string(MaterialKind kind);  // "?" for a value that is no kind

struct Material {
    std::string name;
    MaterialKind kind = MaterialKind::lambertian;
    Vec3 diffuse{0.8f};      // Kd: Lambertian albedo, and the glossy model's diffuse base
    Vec3 specular{0.04f};    // Rs: glossy layer reflectance at normal incidence
    float exponent = 100.f;  // glossy Phong-like exponent (isotropic Ashikhmin-Shirley n)
    float ior = 1.5f;        // dielectric index of refraction (outside is 1)
    Vec3 transmission{1.f};  // dielectric tint
    Vec3 emission{0.f};      // radiance emitted from both sides; nonzero makes it a light

    bool emissive() const { return !is_black(emission); }
};

struct Triangle {
    uint32_t v0 = 0, v1 = 0, v2 = 0;
    uint32_t material = 0;
};

struct Sphere {
    Vec3 center;
    float radius = 1.f;
    uint32_t material = 0;
};

// One area light: a group of emissive primitives sampled together (a quad, a sphere, a mesh).
struct AreaLight {
    std::vector<uint32_t> primitives;  // global primitive ids
    std::vector<float> area_cdf;       // running sum of primitive areas, for area-weighted choice
    float area = 0.f;
    Vec3 emission;
};

struct ThinLensCamera {
    Vec3 eye{0.f, 0.f, 5.f};
    Vec3 look_at{0.f, 0.f, 0.f};
    Vec3 up{0.f, 1.f, 0.f};
    float vertical_fov_degrees = 45.f;
    float aperture_radius = 0.f;  // zero is a pinhole
    float focal_distance = 1.f;   // distance along the view axis to the plane in focus
};

// What a scene needs of a renderer or a hardware model: it decides which filters exist,
// which units are elaborated, and the bytes of a ray record.
struct FeatureSet {
    bool triangles = false;
    bool spheres = false;
    bool lambertian = false;
    bool dielectric = false;
    bool glossy = false;
    bool thin_lens = false;
    bool ambient = false;
    bool environment = false;
    uint32_t light_count = 0;
    // The share of light samples (sample_light, kernels/lights.h: a light at random, then a
    // primitive of it by area) that land on a sphere.
    float sphere_light_share = 0.f;
    // The share of the primitives' surface area on spheres: what the timing models take as the
    // share of hits on spheres (OpCostConfig::sphere_hit_per_lane_cycles). Exact where a scene
    // has one kind (furnace 1, conference 0); the emission filter's lanes of a 64 x 64 frame hit
    // spheres 0.168 of the time on cornell (area 0.140) and 0.027 on atrium (area 0.004).
    float sphere_area_share = 0.f;
    uint32_t max_depth = 0;

    // The flag of one material kind; a switch without default, so a new kind cannot be missed.
    static bool FeatureSet::*material_flag(MaterialKind kind);
    bool uses(MaterialKind kind) const { return this->*material_flag(kind); }
    uint32_t material_kinds() const;  // how many kinds the scene uses
    std::string describe() const;
};

struct Scene;
// Hash of everything in a scene that changes a trace (geometry, materials, camera, lights):
// a trace file's header names the scene it is of by this.
uint64_t scene_hash(const Scene& scene);

struct Scene {
    std::string name;
    // Huge pages (base/huge_pages.h): shading reads a hit's triangle and vertices at random.
    std::vector<Vec3, HugePageAllocator<Vec3>> positions;
    std::vector<Triangle, HugePageAllocator<Triangle>> triangles;
    std::vector<Sphere> spheres;
    std::vector<Material> materials;
    std::vector<AreaLight> lights;  // built by finalize() from emissive primitives
    ThinLensCamera camera;
    Vec3 ambient{0.f};       // constant ambient term: replaces indirect diffuse bounces when set
    Vec3 environment{0.f};   // radiance of rays that leave the scene
    uint32_t max_depth = 3;  // bounces after the camera ray

    uint32_t triangle_count() const { return uint32_t(triangles.size()); }
    uint32_t primitive_count() const { return uint32_t(triangles.size() + spheres.size()); }
    bool is_sphere(uint32_t prim) const { return prim >= triangles.size(); }
    const Sphere& sphere(uint32_t prim) const { return spheres[prim - triangles.size()]; }
    uint32_t material_of(uint32_t prim) const {
        return is_sphere(prim) ? sphere(prim).material : triangles[prim].material;
    }
    float primitive_area(uint32_t prim) const;
    Bounds3 primitive_bounds(uint32_t prim) const;
    Bounds3 bounds() const;

    FeatureSet features() const;
    // Groups emissive primitives into lights: one light per emissive object. `light_groups`
    // gives, per primitive, an object id (same id = same light); empty means one light per
    // emissive sphere and per emissive triangle.
    void finalize(const std::vector<uint32_t>& light_groups = {});
    // Bytes of scene data a tracer reads: vertices, triangles, spheres, materials.
    uint64_t geometry_bytes() const;
};

}  // namespace sfx
