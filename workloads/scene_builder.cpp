// Transform and SceneBuilder (generators.h): how generators place and append primitives.

#include <cmath>
#include <string>

#include "workloads/generator_kit.h"

namespace sfx {

// ---- Transform ----------------------------------------------------------------------------

Transform Transform::make(const Vec3& scale, const Vec3& rotate_degrees, const Vec3& translate) {
    auto mul = [](const float a[3][3], const float b[3][3], float out[3][3]) {
        for (int r = 0; r < 3; ++r)
            for (int c = 0; c < 3; ++c)
                out[r][c] = a[r][0] * b[0][c] + a[r][1] * b[1][c] + a[r][2] * b[2][c];
    };
    const float cx = std::cos(radians(rotate_degrees.x)), sx = std::sin(radians(rotate_degrees.x));
    const float cy = std::cos(radians(rotate_degrees.y)), sy = std::sin(radians(rotate_degrees.y));
    const float cz = std::cos(radians(rotate_degrees.z)), sz = std::sin(radians(rotate_degrees.z));
    const float rx[3][3] = {{1.f, 0.f, 0.f}, {0.f, cx, -sx}, {0.f, sx, cx}};
    const float ry[3][3] = {{cy, 0.f, sy}, {0.f, 1.f, 0.f}, {-sy, 0.f, cy}};
    const float rz[3][3] = {{cz, -sz, 0.f}, {sz, cz, 0.f}, {0.f, 0.f, 1.f}};
    const float s[3][3] = {{scale.x, 0.f, 0.f}, {0.f, scale.y, 0.f}, {0.f, 0.f, scale.z}};
    float a[3][3], b[3][3];
    mul(rx, s, a);
    mul(ry, a, b);
    Transform t;
    mul(rz, b, t.m);
    t.translation = translate;
    return t;
}

Transform Transform::rotate_y(float degrees, const Vec3& translate) {
    return make(Vec3(1.f), Vec3(0.f, degrees, 0.f), translate);
}

// ---- SceneBuilder -------------------------------------------------------------------------

void SceneBuilder::expect(uint64_t more) const {
    const uint64_t have = m_scene.triangles.size() + m_scene.spheres.size();
    if (more > k_max_primitives || have + more > k_max_primitives)
        throw TooManyPrimitives("more than " + std::to_string(k_max_primitives) + " primitives (" +
                                std::to_string(have) + " so far, " + std::to_string(more) +
                                " more asked for)");
}

uint32_t SceneBuilder::add_vertex(const Vec3& p) {
    if (m_scene.positions.size() >= 3 * k_max_primitives)
        throw TooManyPrimitives("more than " + std::to_string(3 * k_max_primitives) + " vertices");
    m_scene.positions.push_back(p);
    return uint32_t(m_scene.positions.size() - 1);
}

void SceneBuilder::add_triangle(uint32_t a, uint32_t b, uint32_t c, uint32_t material) {
    expect(1);
    m_scene.triangles.push_back(Triangle{a, b, c, material});
    m_triangle_objects.push_back(m_object);
}

void SceneBuilder::add_sphere(const Vec3& center, float radius, uint32_t material) {
    expect(1);
    m_scene.spheres.push_back(Sphere{center, radius, material});
    m_sphere_objects.push_back(m_object);
}

std::vector<uint32_t> SceneBuilder::light_groups() const {
    std::vector<uint32_t> groups(m_triangle_objects);
    groups.insert(groups.end(), m_sphere_objects.begin(), m_sphere_objects.end());
    return groups;
}

}  // namespace sfx
