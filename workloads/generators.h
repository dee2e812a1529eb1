#pragma once
// Procedural geometry: a scene builder that remembers which object (light group) every
// primitive belongs to, shape helpers (boxes, grids, lathes, arches, rocks), and the named
// generators a scene file calls (`type: generator`). Generators are pure functions of their
// seed and parameters: no std::random_device, no unordered containers, no clocks.

#include <cstdint>
#include <functional>
#include <stdexcept>
#include <map>
#include <string>
#include <vector>

#include "workloads/scene.h"

namespace sfx {

// Affine transform: p' = linear * p + translation (row-major 3x3).
struct Transform {
    float m[3][3] = {{1.f, 0.f, 0.f}, {0.f, 1.f, 0.f}, {0.f, 0.f, 1.f}};
    Vec3 translation;

    Vec3 apply(const Vec3& p) const {
        return Vec3(m[0][0] * p.x + m[0][1] * p.y + m[0][2] * p.z,
                    m[1][0] * p.x + m[1][1] * p.y + m[1][2] * p.z,
                    m[2][0] * p.x + m[2][1] * p.y + m[2][2] * p.z) +
               translation;
    }
    // Scale, then rotate about x, then y, then z (degrees), then translate.
    static Transform make(const Vec3& scale, const Vec3& rotate_degrees, const Vec3& translate);
    static Transform rotate_y(float degrees, const Vec3& translate = Vec3(0.f));
};

// Thrown by SceneBuilder past k_max_primitives: generator parameters that are each in range
// can together ask for more memory than the machine has.
struct TooManyPrimitives : std::length_error {
    using std::length_error::length_error;
};

// Appends primitives to a scene. Every primitive belongs to the current object; an object with
// an emissive material is one area light, so begin_object() before each light.
class SceneBuilder {
public:
    // 16 times the largest shipped scene; about 1.5 GB with its BVH.
    static constexpr uint64_t k_max_primitives = uint64_t(1) << 25;

    explicit SceneBuilder(Scene& scene) : m_scene(scene) {}

    // Throws TooManyPrimitives now if `more` primitives would pass the limit: generators
    // call it before a large loop, so that the error comes up front.
    void expect(uint64_t more) const;

    uint32_t begin_object() { return ++m_object; }
    uint32_t object() const { return m_object; }

    uint32_t add_vertex(const Vec3& p);
    void add_triangle(uint32_t a, uint32_t b, uint32_t c, uint32_t material);
    void add_sphere(const Vec3& center, float radius, uint32_t material);

    // Light groups per global primitive id (triangles, then spheres) for Scene::finalize().
    std::vector<uint32_t> light_groups() const;
    Scene& scene() { return m_scene; }

private:
    Scene& m_scene;
    std::vector<uint32_t> m_triangle_objects;
    std::vector<uint32_t> m_sphere_objects;
    uint32_t m_object = 0;
};

// Shape helpers. All take the material index and append to the builder's current object.
namespace shapes {

// Two triangles spanning origin, origin+u, origin+u+v, origin+v.
void quad(SceneBuilder& b, const Vec3& origin, const Vec3& u, const Vec3& v, uint32_t material,
          const Transform* xf = nullptr);
// Axis-aligned box (12 triangles), optionally transformed.
void box(SceneBuilder& b, const Vec3& lo, const Vec3& hi, uint32_t material,
         const Transform* xf = nullptr);
// nu x nv grid over the parallelogram (origin, u, v), each vertex moved by
// height(s, t) along normalize(cross(u, v)), with s, t in [0, 1]. 2 * nu * nv triangles.
void grid(SceneBuilder& b, const Vec3& origin, const Vec3& u, const Vec3& v, uint32_t nu,
          uint32_t nv, uint32_t material, const std::function<float(float, float)>& height = {},
          const Transform* xf = nullptr);
// Surface of revolution about +y from `base`: radius(theta, t) at height t * h, t in [0, 1];
// `segments` around, `rings` up; closed with flat caps when `caps`.
void lathe(SceneBuilder& b, const Vec3& base, float h, uint32_t segments, uint32_t rings,
           uint32_t material, const std::function<float(float, float)>& radius, bool caps = true);
// Round arch opening of radius `r` cut into a rectangular slab in the x-y plane of `xf`: the
// slab spans x in [-half_width, half_width] and y in [0, top] (the opening springs at y = 0),
// and is `depth` thick in z. Requires r <= half_width and r < top.
void arch(SceneBuilder& b, float r, float half_width, float top, float depth, uint32_t segments,
          uint32_t material, const Transform& xf);
// A parametric patch: point(s, t) for s, t in [0, 1] on an nu x nv grid (2 * nu * nv triangles).
void surface(SceneBuilder& b, uint32_t nu, uint32_t nv, uint32_t material,
             const std::function<Vec3(float, float)>& point);
// A rough rock: an icosphere subdivided `levels` times (20 * 4^levels triangles) with radial
// noise from `seed`, scaled by `size` (per axis).
void rock(SceneBuilder& b, const Vec3& center, const Vec3& size, uint32_t levels, uint64_t seed,
          float roughness, uint32_t material);

}  // namespace shapes

// Deterministic value noise and hashing for generators.
float hash_float(uint64_t seed, uint64_t a, uint64_t b = 0);  // uniform in [0, 1)
float value_noise(uint64_t seed, float x, float y);            // smooth, in [0, 1)

// A named generator callable from a scene file.
struct GeneratorParam {
    std::string name;
    double value = 0.0;  // the default
    double min = 0.0;
    double max = 0.0;
    bool integer = false;
    std::string help;
};

struct GeneratorInput {
    uint64_t seed = 0;
    std::map<std::string, double> params;      // every declared parameter, defaults filled in
    std::map<std::string, uint32_t> materials;  // role -> material index, every role present
};

struct GeneratorInfo {
    std::string name;
    std::string description;
    std::vector<GeneratorParam> params;
    std::vector<std::string> material_roles;
    std::function<void(const GeneratorInput&, SceneBuilder&)> build;
};

// The registry, in a stable order.
const std::vector<GeneratorInfo>& generators();
const GeneratorInfo* find_generator(const std::string& name);

}  // namespace sfx
