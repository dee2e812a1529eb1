#include "workloads/generators.h"

#include <algorithm>
#include <cmath>
#include <mutex>
#include <utility>

#include "kernels/rng.h"

namespace sfx {

namespace {
constexpr float k_pi = 3.14159265358979323846f;
float radians(float degrees) { return degrees * (k_pi / 180.f); }
}  // namespace

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

// ---- noise --------------------------------------------------------------------------------

float hash_float(uint64_t seed, uint64_t a, uint64_t b) {
    const uint64_t h = mix64(mix64(mix64(seed ^ 0x51ed270b27a3c3d1ull) ^ a) ^ (b * 0x9e3779b97f4a7c15ull));
    return float(h >> 40) * (1.f / 16777216.f);
}

float value_noise(uint64_t seed, float x, float y) {
    const float fx = std::floor(x), fy = std::floor(y);
    const int64_t ix = int64_t(fx), iy = int64_t(fy);
    float tx = x - fx, ty = y - fy;
    tx = tx * tx * (3.f - 2.f * tx);
    ty = ty * ty * (3.f - 2.f * ty);
    auto h = [&](int64_t i, int64_t j) { return hash_float(seed, uint64_t(i), uint64_t(j)); };
    const float a = h(ix, iy) + (h(ix + 1, iy) - h(ix, iy)) * tx;
    const float c = h(ix, iy + 1) + (h(ix + 1, iy + 1) - h(ix, iy + 1)) * tx;
    return a + (c - a) * ty;
}

// ---- shapes -------------------------------------------------------------------------------

namespace shapes {

namespace {
Vec3 place(const Transform* xf, const Vec3& p) { return xf ? xf->apply(p) : p; }
}  // namespace

void quad(SceneBuilder& b, const Vec3& o, const Vec3& u, const Vec3& v, uint32_t material,
          const Transform* xf) {
    const uint32_t a = b.add_vertex(place(xf, o));
    const uint32_t c1 = b.add_vertex(place(xf, o + u));
    const uint32_t c2 = b.add_vertex(place(xf, o + u + v));
    const uint32_t c3 = b.add_vertex(place(xf, o + v));
    b.add_triangle(a, c1, c2, material);
    b.add_triangle(a, c2, c3, material);
}

void box(SceneBuilder& b, const Vec3& lo, const Vec3& hi, uint32_t material, const Transform* xf) {
    uint32_t v[8];
    for (int i = 0; i < 8; ++i)
        v[i] = b.add_vertex(place(xf, Vec3(i & 1 ? hi.x : lo.x, i & 2 ? hi.y : lo.y,
                                           i & 4 ? hi.z : lo.z)));
    static const int faces[6][4] = {{0, 2, 6, 4}, {1, 5, 7, 3}, {0, 4, 5, 1},
                                    {2, 3, 7, 6}, {0, 1, 3, 2}, {4, 6, 7, 5}};
    for (const auto& f : faces) {
        b.add_triangle(v[f[0]], v[f[1]], v[f[2]], material);
        b.add_triangle(v[f[0]], v[f[2]], v[f[3]], material);
    }
}

void grid(SceneBuilder& b, const Vec3& o, const Vec3& u, const Vec3& v, uint32_t nu, uint32_t nv,
          uint32_t material, const std::function<float(float, float)>& height,
          const Transform* xf) {
    const Vec3 n = normalize(cross(u, v));
    const uint32_t first = uint32_t(b.scene().positions.size());
    for (uint32_t j = 0; j <= nv; ++j) {
        const float t = float(j) / float(nv);
        for (uint32_t i = 0; i <= nu; ++i) {
            const float s = float(i) / float(nu);
            Vec3 p = o + u * s + v * t;
            if (height) p += n * height(s, t);
            b.add_vertex(place(xf, p));
        }
    }
    const uint32_t row = nu + 1;
    for (uint32_t j = 0; j < nv; ++j)
        for (uint32_t i = 0; i < nu; ++i) {
            const uint32_t a = first + j * row + i;
            b.add_triangle(a, a + 1, a + row + 1, material);
            b.add_triangle(a, a + row + 1, a + row, material);
        }
}

void lathe(SceneBuilder& b, const Vec3& base, float h, uint32_t segments, uint32_t rings,
           uint32_t material, const std::function<float(float, float)>& radius, bool caps) {
    const uint32_t first = uint32_t(b.scene().positions.size());
    for (uint32_t j = 0; j <= rings; ++j) {
        const float t = float(j) / float(rings);
        for (uint32_t i = 0; i < segments; ++i) {
            const float theta = 2.f * k_pi * float(i) / float(segments);
            const float r = radius(theta, t);
            b.add_vertex(base + Vec3(r * std::cos(theta), t * h, r * std::sin(theta)));
        }
    }
    for (uint32_t j = 0; j < rings; ++j)
        for (uint32_t i = 0; i < segments; ++i) {
            const uint32_t i1 = (i + 1) % segments;
            const uint32_t a = first + j * segments + i, c = first + j * segments + i1;
            const uint32_t d = a + segments, e = c + segments;
            b.add_triangle(a, d, e, material);
            b.add_triangle(a, e, c, material);
        }
    if (!caps) return;
    const uint32_t bottom = b.add_vertex(base);
    const uint32_t top = b.add_vertex(base + Vec3(0.f, h, 0.f));
    for (uint32_t i = 0; i < segments; ++i) {
        const uint32_t i1 = (i + 1) % segments;
        b.add_triangle(bottom, first + i1, first + i, material);
        b.add_triangle(top, first + rings * segments + i, first + rings * segments + i1, material);
    }
}

void arch(SceneBuilder& b, float r, float half_width, float top, float depth, uint32_t segments,
          uint32_t material, const Transform& xf) {
    const float hw = half_width;
    // Angles along the opening, with the two slab corners inserted so the outer outline
    // follows the rectangle exactly.
    std::vector<float> angles;
    for (uint32_t i = 0; i <= segments; ++i) angles.push_back(k_pi * float(i) / float(segments));
    const float corner = std::atan2(top, hw);
    angles.push_back(corner);
    angles.push_back(k_pi - corner);
    std::sort(angles.begin(), angles.end());
    angles.erase(std::unique(angles.begin(), angles.end(),
                             [](float a, float c) { return std::fabs(a - c) < 1e-6f; }),
                 angles.end());
    auto outer = [&](float theta, float z) {
        const float c = std::cos(theta), s = std::sin(theta);
        float t = INFINITY;
        if (std::fabs(c) > 1e-6f) t = std::min(t, hw / std::fabs(c));
        if (s > 1e-6f) t = std::min(t, top / s);
        return Vec3(c * t, s * t, z);
    };
    auto inner = [&](float theta, float z) {
        return Vec3(r * std::cos(theta), r * std::sin(theta), z);
    };
    const float hz = depth * 0.5f;
    for (size_t k = 0; k + 1 < angles.size(); ++k) {
        const float t0 = angles[k], t1 = angles[k + 1];
        for (int side = 0; side < 2; ++side) {  // the two faces of the slab
            const float z = side ? -hz : hz;
            const uint32_t a = b.add_vertex(xf.apply(inner(t0, z)));
            const uint32_t c = b.add_vertex(xf.apply(inner(t1, z)));
            const uint32_t d = b.add_vertex(xf.apply(outer(t1, z)));
            const uint32_t e = b.add_vertex(xf.apply(outer(t0, z)));
            b.add_triangle(a, c, d, material);
            b.add_triangle(a, d, e, material);
        }
        // Intrados: the curved underside of the opening.
        const uint32_t a = b.add_vertex(xf.apply(inner(t0, hz)));
        const uint32_t c = b.add_vertex(xf.apply(inner(t1, hz)));
        const uint32_t d = b.add_vertex(xf.apply(inner(t1, -hz)));
        const uint32_t e = b.add_vertex(xf.apply(inner(t0, -hz)));
        b.add_triangle(a, c, d, material);
        b.add_triangle(a, d, e, material);
    }
    // Springing ledges between the opening and the slab's edges, and the slab's top.
    if (hw > r) {
        quad(b, Vec3(r, 0.f, hz), Vec3(hw - r, 0.f, 0.f), Vec3(0.f, 0.f, -depth), material, &xf);
        quad(b, Vec3(-hw, 0.f, hz), Vec3(hw - r, 0.f, 0.f), Vec3(0.f, 0.f, -depth), material, &xf);
    }
    quad(b, Vec3(-hw, top, hz), Vec3(2.f * hw, 0.f, 0.f), Vec3(0.f, 0.f, -depth), material, &xf);
}

void surface(SceneBuilder& b, uint32_t nu, uint32_t nv, uint32_t material,
             const std::function<Vec3(float, float)>& point) {
    const uint32_t first = uint32_t(b.scene().positions.size());
    for (uint32_t j = 0; j <= nv; ++j)
        for (uint32_t i = 0; i <= nu; ++i) b.add_vertex(point(float(i) / float(nu), float(j) / float(nv)));
    const uint32_t row = nu + 1;
    for (uint32_t j = 0; j < nv; ++j)
        for (uint32_t i = 0; i < nu; ++i) {
            const uint32_t a = first + j * row + i;
            b.add_triangle(a, a + 1, a + row + 1, material);
            b.add_triangle(a, a + row + 1, a + row, material);
        }
}

namespace {
struct IcoMesh {
    std::vector<Vec3> vertices;
    std::vector<uint32_t> indices;
};

const IcoMesh& icosphere(uint32_t levels) {
    // Built once per level and shared; std::map nodes never move, so references stay valid.
    static std::mutex mutex;
    static std::map<uint32_t, IcoMesh> cache;
    std::lock_guard<std::mutex> lock(mutex);
    auto found = cache.find(levels);
    if (found != cache.end()) return found->second;
    IcoMesh m;
    const float t = (1.f + std::sqrt(5.f)) * 0.5f;
    const Vec3 v[12] = {{-1, t, 0}, {1, t, 0}, {-1, -t, 0}, {1, -t, 0}, {0, -1, t}, {0, 1, t},
                        {0, -1, -t}, {0, 1, -t}, {t, 0, -1}, {t, 0, 1}, {-t, 0, -1}, {-t, 0, 1}};
    for (const Vec3& p : v) m.vertices.push_back(normalize(p));
    m.indices = {0, 11, 5, 0, 5, 1, 0, 1, 7, 0, 7, 10, 0, 10, 11, 1, 5, 9, 5, 11, 4,
                 11, 10, 2, 10, 7, 6, 7, 1, 8, 3, 9, 4, 3, 4, 2, 3, 2, 6, 3, 6, 8,
                 3, 8, 9, 4, 9, 5, 2, 4, 11, 6, 2, 10, 8, 6, 7, 9, 8, 1};
    for (uint32_t l = 0; l < levels; ++l) {
        std::map<std::pair<uint32_t, uint32_t>, uint32_t> mid;
        auto midpoint = [&](uint32_t a, uint32_t c) {
            const auto key = std::make_pair(std::min(a, c), std::max(a, c));
            auto it = mid.find(key);
            if (it != mid.end()) return it->second;
            m.vertices.push_back(normalize(m.vertices[a] + m.vertices[c]));
            const uint32_t id = uint32_t(m.vertices.size() - 1);
            mid.emplace(key, id);
            return id;
        };
        std::vector<uint32_t> next;
        for (size_t i = 0; i < m.indices.size(); i += 3) {
            const uint32_t a = m.indices[i], c = m.indices[i + 1], d = m.indices[i + 2];
            const uint32_t ab = midpoint(a, c), bc = midpoint(c, d), ca = midpoint(d, a);
            next.insert(next.end(), {a, ab, ca, c, bc, ab, d, ca, bc, ab, bc, ca});
        }
        m.indices.swap(next);
    }
    return cache.emplace(levels, std::move(m)).first->second;
}
}  // namespace

void rock(SceneBuilder& b, const Vec3& center, const Vec3& size, uint32_t levels, uint64_t seed,
          float roughness, uint32_t material) {
    const IcoMesh& ico = icosphere(levels);
    // Radial displacement: a few random smooth waves over the sphere's directions.
    Vec3 dirs[4];
    float phase[4], freq[4];
    for (int k = 0; k < 4; ++k) {
        const float z = 2.f * hash_float(seed, 10 + k) - 1.f;
        const float a = 2.f * k_pi * hash_float(seed, 20 + k);
        const float s = std::sqrt(std::max(0.f, 1.f - z * z));
        dirs[k] = Vec3(s * std::cos(a), z, s * std::sin(a));
        phase[k] = 2.f * k_pi * hash_float(seed, 30 + k);
        freq[k] = 1.5f + 3.f * hash_float(seed, 40 + k);
    }
    const uint32_t first = uint32_t(b.scene().positions.size());
    for (const Vec3& n : ico.vertices) {
        float r = 1.f;
        for (int k = 0; k < 4; ++k) r += roughness * 0.25f * std::sin(freq[k] * dot(n, dirs[k]) + phase[k]);
        b.add_vertex(center + n * size * r);
    }
    for (size_t i = 0; i < ico.indices.size(); i += 3)
        b.add_triangle(first + ico.indices[i], first + ico.indices[i + 1],
                       first + ico.indices[i + 2], material);
}

}  // namespace shapes

// ---- generators -------------------------------------------------------------------------

namespace {

struct Ctx {
    const GeneratorInput& in;
    SceneBuilder& b;
    double p(const char* name) const { return in.params.at(name); }
    uint32_t n(const char* name) const { return uint32_t(in.params.at(name)); }
    uint32_t m(const char* role) const { return in.materials.at(role); }
};

float smoothstep(float e0, float e1, float x) {
    const float t = std::min(1.f, std::max(0.f, (x - e0) / (e1 - e0)));
    return t * t * (3.f - 2.f * t);
}

// Atrium: a two-storey arcaded courtyard (Sponza-like) under a sky panel, with a fountain,
// glass and metal spheres, balustrades and hanging cloths.
void build_atrium(const GeneratorInput& in, SceneBuilder& b) {
    const Ctx c{in, b};
    const uint32_t bays = c.n("bays");
    const float bay = 3.f;
    const float half_l = 0.5f * bay * float(bays);
    const float court = 6.f, gallery = 9.f;  // courtyard half width, gallery back wall
    const float h1 = 5.f, h2 = 9.7f, h_top = 11.5f;
    const uint32_t col_seg = c.n("column_segments"), col_rings = c.n("column_rings");
    const uint32_t arch_seg = c.n("arch_segments");
    const uint32_t stone = c.m("stone"), floor_a = c.m("floor"), floor_b = c.m("floor_dark");

    // Courtyard and gallery floors: checkered marble tiles.
    for (int iz = 0; iz < int(2.f * gallery); ++iz)
        for (int ix = 0; ix < int(bay) * int(bays); ++ix)
            shapes::quad(b, Vec3(-half_l + float(ix), 0.f, -gallery + float(iz)),
                         Vec3(0.f, 0.f, 1.f), Vec3(1.f, 0.f, 0.f),
                         ((ix + iz) & 1) ? floor_a : floor_b);
    // Walls: gallery backs, end walls, and the attic parapet above the arcades.
    for (int s = -1; s <= 1; s += 2) {
        const float z = float(s) * gallery;
        shapes::box(b, Vec3(-half_l, 0.f, std::min(z, z + s * 0.4f)),
                    Vec3(half_l, h_top, std::max(z, z + s * 0.4f)), stone);
        shapes::box(b, Vec3(-half_l, h2, std::min(s * court - 0.3f, s * court + 0.3f)),
                    Vec3(half_l, h_top, std::max(s * court - 0.3f, s * court + 0.3f)), stone);
        const float x = float(s) * half_l;
        shapes::box(b, Vec3(std::min(x, x + s * 0.4f), 0.f, -gallery),
                    Vec3(std::max(x, x + s * 0.4f), h_top, gallery), stone);
    }
    // Per side and storey: columns, arches, floor slab over the gallery, cornice.
    auto column = [&](const Vec3& base, float height) {
        shapes::lathe(b, base, height, col_seg, col_rings, stone, [](float, float t) {
            if (t < 0.06f) return 0.34f;
            if (t < 0.1f) return 0.34f - 0.1f * smoothstep(0.06f, 0.1f, t);
            if (t > 0.9f) return 0.24f + 0.12f * smoothstep(0.9f, 0.97f, t);
            return 0.24f - 0.02f * t;  // entasis
        });
    };
    const uint32_t curtain_res = c.n("curtain_resolution");
    const uint32_t cloths[3] = {c.m("cloth_red"), c.m("cloth_blue"), c.m("cloth_green")};
    for (int s = -1; s <= 1; s += 2) {
        const float z = float(s) * court;
        const float floors[2] = {0.f, h1 + 0.2f};
        const float springs[2] = {3.f, h1 + 0.2f + 2.6f};
        const float tops[2] = {h1, h2};
        for (int storey = 0; storey < 2; ++storey) {
            for (uint32_t i = 0; i <= bays; ++i)
                column(Vec3(-half_l + bay * float(i), floors[storey], z), springs[storey] - floors[storey]);
            for (uint32_t i = 0; i < bays; ++i) {
                const float cx = -half_l + bay * (float(i) + 0.5f);
                const Transform xf = Transform::make(Vec3(1.f), Vec3(0.f), Vec3(cx, springs[storey], z));
                shapes::arch(b, 0.5f * bay - 0.3f, 0.5f * bay, tops[storey] - springs[storey], 0.6f,
                             arch_seg, stone, xf);
            }
            // Slab over the gallery and a cornice along the arcade.
            const float zb = s > 0 ? z - 0.3f : z + 0.3f;
            shapes::box(b, Vec3(-half_l, tops[storey], std::min(zb, float(s) * gallery)),
                        Vec3(half_l, tops[storey] + 0.2f, std::max(zb, float(s) * gallery)), stone);
            shapes::box(b, Vec3(-half_l, tops[storey], z - 0.45f),
                        Vec3(half_l, tops[storey] + 0.3f, z + 0.45f), stone);
        }
        // Upper balustrade: rail, plinth and turned balusters in every bay.
        const float fy = h1 + 0.2f;
        const uint32_t per_bay = c.n("balusters_per_bay");
        const uint32_t bal_seg = c.n("baluster_segments"), bal_rings = c.n("baluster_rings");
        for (uint32_t i = 0; i < bays; ++i) {
            const float x0 = -half_l + bay * float(i) + 0.3f, x1 = x0 + bay - 0.6f;
            shapes::box(b, Vec3(x0, fy, z - 0.15f), Vec3(x1, fy + 0.12f, z + 0.15f), stone);
            shapes::box(b, Vec3(x0, fy + 0.9f, z - 0.17f), Vec3(x1, fy + 1.f, z + 0.17f), stone);
            for (uint32_t k = 0; k < per_bay; ++k) {
                const float x = x0 + (x1 - x0) * (float(k) + 0.5f) / float(per_bay);
                shapes::lathe(b, Vec3(x, fy + 0.12f, z), 0.78f, bal_seg, bal_rings, stone,
                              [](float, float t) {
                                  return 0.045f + 0.04f * std::sin(3.14159f * std::pow(t, 0.7f)) -
                                         0.015f * std::sin(6.2832f * t);
                              });
            }
            // Cloths hang from the upper arches in alternate bays, with folds.
            if ((i + (s > 0 ? 1u : 0u)) % 2 == 0) {
                const float cz = z - float(s) * 0.45f;
                const uint32_t cloth = cloths[(i / 2 + (s > 0)) % 3];
                shapes::surface(b, curtain_res, curtain_res * 2, cloth, [&](float u, float v) {
                    const float x = x0 + 0.15f + (x1 - x0 - 0.3f) * u;
                    const float y = springs[1] + 1.2f - 3.6f * v;
                    const float fold = 0.08f * std::sin(u * 6.f * 3.14159f) * (0.3f + v);
                    return Vec3(x, y, cz - float(s) * (fold + 0.25f * v * v));
                });
            }
        }
    }
    // End walls: blind arcades on pilasters continue the rhythm of the long sides.
    const float end_bays[6] = {-gallery, -court, -2.f, 2.f, court, gallery};
    for (int s = -1; s <= 1; s += 2) {
        const float x = float(s) * (half_l - 0.15f);
        for (int storey = 0; storey < 2; ++storey) {
            const float floor_y = storey ? h1 + 0.2f : 0.f, spring = storey ? h1 + 2.8f : 3.f;
            const float top = storey ? h2 : h1;
            for (int k = 0; k < 5; ++k) {
                const float z0 = end_bays[k], z1 = end_bays[k + 1];
                const float half_w = 0.5f * (z1 - z0);
                const Transform xf = Transform::rotate_y(90.f, Vec3(x, spring, 0.5f * (z0 + z1)));
                shapes::arch(b, half_w - 0.3f, half_w, top - spring, 0.3f, arch_seg, stone, xf);
            }
            for (int k = 0; k < 6; ++k)
                shapes::box(b, Vec3(x - 0.2f, floor_y, end_bays[k] - 0.3f),
                            Vec3(x + 0.2f, spring, end_bays[k] + 0.3f), stone);
        }
    }
    // Courtyard: a fountain with a glass sphere, pedestals with glass and metal spheres,
    // and planters with shrubs.
    const uint32_t glass = c.m("glass"), metal = c.m("metal"), plant = c.m("plant");
    shapes::lathe(b, Vec3(0.f, 0.f, 0.f), 0.6f, 64, 12, stone, [](float, float t) {
        return 2.f - 0.3f * t;  // basin wall
    });
    shapes::lathe(b, Vec3(0.f, 0.f, 0.f), 1.3f, 32, 16, stone, [](float, float t) {
        return 0.25f + 0.35f * smoothstep(0.75f, 1.f, t);  // the central stem and bowl
    });
    b.add_sphere(Vec3(0.f, 1.9f, 0.f), 0.6f, glass);
    const uint32_t pedestals = c.n("pedestals");
    for (uint32_t k = 0; k < pedestals; ++k) {
        const float x = -half_l + 2.5f + (2.f * half_l - 5.f) * float(k) / float(std::max(1u, pedestals - 1));
        for (int s = -1; s <= 1; s += 2) {
            const float z = float(s) * (court - 1.5f);
            shapes::box(b, Vec3(x - 0.3f, 0.f, z - 0.3f), Vec3(x + 0.3f, 1.f, z + 0.3f), stone);
            b.add_sphere(Vec3(x, 1.35f, z), 0.35f, (k + (s > 0)) % 2 ? glass : metal);
        }
    }
    const uint32_t rock_levels = c.n("shrub_detail");
    for (int corner = 0; corner < 4; ++corner) {
        const float x = (corner & 1 ? 1.f : -1.f) * (half_l - 2.f);
        const float z = (corner & 2 ? 1.f : -1.f) * (court - 1.6f);
        shapes::box(b, Vec3(x - 0.7f, 0.f, z - 0.7f), Vec3(x + 0.7f, 0.6f, z + 0.7f), stone);
        for (int k = 0; k < 3; ++k)
            shapes::rock(b, Vec3(x + 0.3f * float(k - 1), 1.1f + 0.2f * float(k % 2), z),
                         Vec3(0.55f, 0.6f, 0.55f), rock_levels, in.seed * 131 + corner * 7 + k, 0.5f,
                         plant);
    }
    // Lights: the sky over the courtyard and a lantern above the fountain.
    b.begin_object();
    shapes::quad(b, Vec3(-half_l, h_top, -court), Vec3(2.f * half_l, 0.f, 0.f),
                 Vec3(0.f, 0.f, 2.f * court), c.m("sky"));
    b.begin_object();
    b.add_sphere(Vec3(0.f, 6.5f, 0.f), 0.3f, c.m("lantern"));
    b.begin_object();
}

// One office chair facing +z (backrest at -z), built around the origin and moved by `xf`.
void office_chair(SceneBuilder& b, const Transform& xf, uint32_t detail, uint32_t fabric,
                  uint32_t frame) {
    const uint32_t first_vertex = uint32_t(b.scene().positions.size());
    const uint32_t seg = detail;
    // Five-star base with casters.
    for (int k = 0; k < 5; ++k) {
        const Transform leg = Transform::rotate_y(72.f * float(k) + 18.f);
        shapes::box(b, Vec3(0.f, 0.06f, -0.025f), Vec3(0.32f, 0.1f, 0.025f), frame, &leg);
        const Vec3 tip = leg.apply(Vec3(0.3f, 0.f, 0.f));
        shapes::lathe(b, tip, 0.06f, seg / 2, seg / 4, frame, [](float, float t) {
            return 0.008f + 0.022f * std::sin(3.14159f * t);
        });
    }
    shapes::lathe(b, Vec3(0.f, 0.08f, 0.f), 0.36f, seg, 4, frame,
                  [](float, float t) { return t < 0.5f ? 0.035f : 0.025f; });
    // Seat: a shell and a cushion bulging up.
    shapes::box(b, Vec3(-0.26f, 0.42f, -0.26f), Vec3(0.26f, 0.45f, 0.24f), frame);
    shapes::surface(b, seg, seg, fabric, [](float u, float v) {
        const float x = -0.25f + 0.5f * u, z = 0.23f - 0.48f * v;
        const float su = 2.f * u - 1.f, sv = 2.f * v - 1.f;
        const float bulge = (1.f - su * su * su * su) * (1.f - sv * sv * sv * sv);
        return Vec3(x, 0.45f + 0.06f * bulge, z);
    });
    // Backrest: a curved, reclined pad (front and back skins).
    for (int side = 0; side < 2; ++side) {
        shapes::surface(b, seg, seg, side ? frame : fabric, [side](float u, float v) {
            const float x = -0.24f + 0.48f * (side ? 1.f - u : u);
            const float y = 0.56f + 0.5f * v;
            const float sx = x / 0.24f;
            const float thick = side ? 0.f : 0.04f * (1.f - sx * sx * sx * sx) *
                                                  std::sin(3.14159f * v);
            const float z = -0.27f - 0.12f * v + 0.08f * sx * sx - thick + (side ? -0.02f : 0.f);
            return Vec3(x, y, z);
        });
    }
    // Armrests on posts.
    for (int s = -1; s <= 1; s += 2) {
        const float x = 0.29f * float(s);
        shapes::box(b, Vec3(x - 0.03f, 0.66f, -0.2f), Vec3(x + 0.03f, 0.69f, 0.12f), frame);
        shapes::lathe(b, Vec3(x, 0.45f, -0.05f), 0.21f, seg / 2, 2, frame,
                      [](float, float) { return 0.015f; });
    }
    // The chair was built around the origin; move it into place.
    auto& positions = b.scene().positions;
    for (size_t i = first_vertex; i < positions.size(); ++i) positions[i] = xf.apply(positions[i]);
}

// Conference room: a long table with chairs around it and along the walls, wood wainscot, a
// whiteboard, and a ceiling of 12 x 6 light panels (72 area lights).
void build_conference(const GeneratorInput& in, SceneBuilder& b) {
    const Ctx c{in, b};
    const float hx = 10.f, hz = 5.f, h = 3.2f;
    const uint32_t wall = c.m("wall"), carpet = c.m("carpet"), wood = c.m("wood");
    const uint32_t metal = c.m("metal"), ceiling = c.m("ceiling"), board = c.m("whiteboard");
    const uint32_t detail = c.n("chair_detail");
    const uint32_t fabrics[2] = {c.m("fabric"), c.m("fabric_alt")};
    // Shell: carpet floor (tiles), walls, ceiling.
    shapes::grid(b, Vec3(-hx, 0.f, -hz), Vec3(0.f, 0.f, 2.f * hz), Vec3(2.f * hx, 0.f, 0.f), 20, 10,
                 carpet);
    shapes::quad(b, Vec3(-hx, h, -hz), Vec3(2.f * hx, 0.f, 0.f), Vec3(0.f, 0.f, 2.f * hz), ceiling);
    shapes::quad(b, Vec3(-hx, 0.f, -hz), Vec3(0.f, h, 0.f), Vec3(2.f * hx, 0.f, 0.f), wall);
    shapes::quad(b, Vec3(-hx, 0.f, hz), Vec3(2.f * hx, 0.f, 0.f), Vec3(0.f, h, 0.f), wall);
    shapes::quad(b, Vec3(-hx, 0.f, -hz), Vec3(0.f, 0.f, 2.f * hz), Vec3(0.f, h, 0.f), wall);
    shapes::quad(b, Vec3(hx, 0.f, -hz), Vec3(0.f, h, 0.f), Vec3(0.f, 0.f, 2.f * hz), wall);
    // Wood wainscot panels with a rail along the long walls, and a whiteboard at the far end.
    for (int s = -1; s <= 1; s += 2) {
        for (int k = 0; k < 16; ++k) {
            const float x0 = -hx + 0.1f + 1.25f * float(k);
            const float z = float(s) * (hz - 0.02f);
            shapes::box(b, Vec3(x0, 0.1f, std::min(z, z - s * 0.03f)),
                        Vec3(x0 + 1.1f, 0.95f, std::max(z, z - s * 0.03f)), wood);
        }
        shapes::box(b, Vec3(-hx, 0.97f, s > 0 ? hz - 0.06f : -hz),
                    Vec3(hx, 1.02f, s > 0 ? hz : -hz + 0.06f), wood);
    }
    shapes::box(b, Vec3(hx - 0.05f, 0.9f, -2.f), Vec3(hx - 0.02f, 2.2f, 2.f), board);
    shapes::box(b, Vec3(hx - 0.08f, 0.86f, -2.05f), Vec3(hx - 0.02f, 0.9f, 2.05f), metal);
    // The table: a racetrack top on pedestals, with a notepad and a cup at every place.
    const float table_half = 5.f, table_w = 1.2f, top_y = 0.75f;
    shapes::box(b, Vec3(-table_half, top_y - 0.05f, -table_w), Vec3(table_half, top_y, table_w), wood);
    for (int s = -1; s <= 1; s += 2)
        shapes::lathe(b, Vec3(float(s) * table_half, top_y - 0.05f, 0.f), 0.05f, 96, 1, wood,
                      [](float, float) { return 1.2f; });
    for (int k = -2; k <= 2; ++k)
        shapes::box(b, Vec3(2.f * float(k) - 0.2f, 0.f, -0.5f), Vec3(2.f * float(k) + 0.2f, top_y - 0.05f, 0.5f),
                    metal);
    const uint32_t per_side = c.n("chairs_per_side");
    const uint32_t cup_seg = c.n("cup_segments");
    auto place_setting = [&](float x, float z, float facing) {
        const Transform xf = Transform::rotate_y(facing, Vec3(x, top_y, z));
        shapes::box(b, Vec3(-0.1f, 0.f, -0.15f), Vec3(0.1f, 0.01f, 0.15f), c.m("paper"), &xf);
        const Vec3 cup = xf.apply(Vec3(0.22f, 0.f, -0.05f));
        shapes::lathe(b, cup, 0.12f, cup_seg, cup_seg / 2, metal,
                      [](float, float t) { return 0.032f + 0.01f * t; });
    };
    uint32_t chair_index = 0;
    auto chair = [&](float x, float z, float facing) {
        const bool alt = hash_float(in.seed, chair_index++, 9) < 0.35f;
        office_chair(b, Transform::rotate_y(facing, Vec3(x, 0.f, z)), detail, fabrics[alt], metal);
    };
    for (uint32_t i = 0; i < per_side; ++i) {
        const float x = -table_half + 0.5f + (2.f * table_half - 1.f) * (float(i) + 0.5f) / float(per_side);
        const float jitter = 6.f * (hash_float(in.seed, i, 1) - 0.5f);
        chair(x, -table_w - 0.55f, jitter);  // faces +z, toward the table
        chair(x, table_w + 0.55f, 180.f + jitter);
        place_setting(x, -table_w + 0.35f, 180.f);
        place_setting(x, table_w - 0.35f, 0.f);
    }
    chair(-table_half - 1.6f, 0.f, 90.f);
    chair(table_half + 1.6f, 0.f, -90.f);
    // A second row along the long walls for observers.
    const uint32_t wall_chairs = c.n("wall_chairs_per_side");
    for (uint32_t i = 0; i < wall_chairs; ++i) {
        const float x = -hx + 1.f + (2.f * hx - 2.f) * (float(i) + 0.5f) / float(wall_chairs);
        chair(x, -hz + 0.6f, 0.f);
        chair(x, hz - 0.6f, 180.f);
    }
    // Ceiling: 12 x 6 light panels, each its own area light, in metal trims.
    for (int i = 0; i < 12; ++i)
        for (int j = 0; j < 6; ++j) {
            const float x = -hx + 20.f / 12.f * (float(i) + 0.5f) - 0.3f;
            const float z = -hz + 10.f / 6.f * (float(j) + 0.5f) - 0.6f;
            b.begin_object();
            shapes::quad(b, Vec3(x, h - 0.03f, z), Vec3(0.6f, 0.f, 0.f), Vec3(0.f, 0.f, 1.2f),
                         c.m("panel"));
            b.begin_object();
            shapes::box(b, Vec3(x - 0.04f, h - 0.04f, z - 0.04f), Vec3(x + 0.64f, h - 0.03f, z), metal);
            shapes::box(b, Vec3(x - 0.04f, h - 0.04f, z + 1.2f), Vec3(x + 0.64f, h - 0.03f, z + 1.24f), metal);
        }
}

// Bas-relief of an Egyptian temple wall, as a height (m, towards the room) at (u, v) metres
// along and up the wall: stone courses, registers of walking figures, columns of glyphs.
float temple_relief(uint64_t seed, float u, float v) {
    float h = 0.004f * value_noise(seed, u * 9.f, v * 9.f);
    // Stone courses and joints.
    const float course = 0.55f;
    const int row = int(std::floor(v / course));
    const float fv = v / course - float(row);
    const float bu = (u + float(row & 1) * 0.55f) / 1.1f;
    const float fu = bu - std::floor(bu);
    if (fv < 0.025f || fu < 0.012f) h -= 0.008f;
    if (v < 0.6f || v > 8.0f) return h;
    const float reg_h = 1.85f;
    const int reg = int((v - 0.6f) / reg_h);
    const float y = v - 0.6f - float(reg) * reg_h;
    if (y < 0.07f) return h + 0.02f;  // raised ground line of the register
    const float spacing = 1.5f;
    const int cell = int(std::floor(u / spacing));
    const float x0 = u - (float(cell) + 0.5f) * spacing;
    const uint64_t id = uint64_t(int64_t(cell) * 8 + reg);
    const float facing = hash_float(seed, id, 1) < 0.5f ? -1.f : 1.f;
    const float x = x0 * facing;
    const float s = 0.9f + 0.15f * hash_float(seed, id, 2);
    // Figure: union of rounded parts, each a bulge sqrt(1 - d^2) inside its outline.
    float f = 0.f;
    auto ellipse = [&](float cx, float cy, float rx, float ry) {
        const float dx = (x - cx * s) / (rx * s), dy = (y - cy * s) / (ry * s);
        const float d2 = dx * dx + dy * dy;
        if (d2 < 1.f) f = std::max(f, std::sqrt(1.f - d2));
    };
    auto bar = [&](float ax, float ay, float bx, float by, float w) {
        const float px = x - ax * s, py = y - ay * s, qx = (bx - ax) * s, qy = (by - ay) * s;
        const float t = std::min(1.f, std::max(0.f, (px * qx + py * qy) / (qx * qx + qy * qy)));
        const float dx = px - qx * t, dy = py - qy * t;
        const float d2 = (dx * dx + dy * dy) / (w * w * s * s);
        if (d2 < 1.f) f = std::max(f, std::sqrt(1.f - d2));
    };
    if (std::fabs(x0) < 0.5f) {
        const bool offering = hash_float(seed, id, 3) < 0.5f;
        bar(-0.1f, 0.1f, -0.02f, 0.75f, 0.05f);   // back leg
        bar(0.14f, 0.1f, 0.03f, 0.75f, 0.05f);    // front leg (striding)
        ellipse(0.f, 0.92f, 0.17f, 0.25f);        // kilt
        ellipse(0.f, 1.25f, 0.15f, 0.22f);        // torso
        ellipse(0.03f, 1.56f, 0.09f, 0.11f);      // head
        bar(0.f, 1.64f, 0.f, 1.8f, 0.055f);       // crown
        if (offering) {
            bar(0.08f, 1.38f, 0.33f, 1.45f, 0.035f);  // raised arms holding a bowl
            ellipse(0.38f, 1.5f, 0.08f, 0.04f);
        } else {
            bar(0.08f, 1.38f, 0.28f, 1.1f, 0.035f);   // arm holding a staff
            bar(0.3f, 0.1f, 0.3f, 1.75f, 0.02f);
        }
    } else {
        // Column of glyphs between figures: recessed signs on a grid.
        const float gx = (std::fabs(x0) - 0.52f) / 0.2f;
        if (gx > 0.f && gx < 1.f && y > 0.2f && y < 1.75f) {
            const int gi = int((y - 0.2f) / 0.1f);
            const float gy = (y - 0.2f) / 0.1f - float(gi);
            const uint64_t g = id * 64 + uint64_t(gi) * 2 + (x0 > 0.f);
            const float kind = hash_float(seed, g, 7);
            bool in = false;
            if (kind < 0.35f) in = (gx - 0.5f) * (gx - 0.5f) + (gy - 0.5f) * (gy - 0.5f) < 0.12f;
            else if (kind < 0.7f) in = gy > 0.35f && gy < 0.65f && gx > 0.15f && gx < 0.85f;
            else if (kind < 0.85f) in = std::fabs(gx - 0.5f) < 0.15f && gy > 0.1f && gy < 0.9f;
            if (in) h -= 0.012f;
        }
    }
    return h + 0.05f * f;
}

// Temple: an Egyptian hypostyle hall (after Kalabsha): rows of papyrus-bundle columns under
// architraves, walls covered in bas-reliefs, two seated colossi before the lit sanctuary door,
// rubble everywhere. Light comes from a roof slot over the aisle and from the sanctuary.
void build_temple(const GeneratorInput& in, SceneBuilder& b) {
    const Ctx c{in, b};
    const float hx = 9.f, z_front = 10.f, z_back = -20.f, wall_h = 8.f, roof = 9.6f;
    const uint32_t stone = c.m("stone"), relief = c.m("relief"), floor_m = c.m("floor");
    const uint64_t seed = in.seed;
    // Floor: paving slabs of slightly uneven height.
    for (int iz = 0; iz < int(z_front - z_back); ++iz)
        for (int ix = 0; ix < int(2.f * hx); ++ix) {
            const float x = -hx + float(ix), z = z_back + float(iz);
            const float top = -0.012f * hash_float(seed, uint64_t(ix), uint64_t(iz) + 1000);
            shapes::box(b, Vec3(x + 0.004f, -0.2f, z + 0.004f), Vec3(x + 0.996f, top, z + 0.996f),
                        floor_m);
        }
    // Relief walls (left, right, and the back wall around the sanctuary door).
    const uint32_t density = c.n("relief_density");  // grid cells per metre
    const float len = z_front - z_back;
    auto side_height = [seed, len](float reverse) {
        return [seed, len, reverse](float s, float t) {
            return temple_relief(seed, (reverse > 0.f ? 1.f - s : s) * len, t * 8.f);
        };
    };
    shapes::grid(b, Vec3(-hx, 0.f, z_front), Vec3(0.f, 0.f, -len), Vec3(0.f, wall_h, 0.f),
                 uint32_t(len * float(density)), uint32_t(wall_h * float(density)), relief,
                 side_height(1.f));
    shapes::grid(b, Vec3(hx, 0.f, z_back), Vec3(0.f, 0.f, len), Vec3(0.f, wall_h, 0.f),
                 uint32_t(len * float(density)), uint32_t(wall_h * float(density)), relief,
                 side_height(0.f));
    const float door = 1.0f, door_h = 4.f;
    const float back_w = hx - door;
    for (int s = -1; s <= 1; s += 2) {
        const float x0 = s < 0 ? -hx : door;
        shapes::grid(b, Vec3(x0, 0.f, z_back), Vec3(back_w, 0.f, 0.f), Vec3(0.f, wall_h, 0.f),
                     uint32_t(back_w * float(density)), uint32_t(wall_h * float(density)), relief,
                     [seed, x0, back_w](float u, float v) {
                         return temple_relief(seed + 1, 40.f + x0 + u * back_w, v * 8.f);
                     });
    }
    shapes::grid(b, Vec3(-door, door_h, z_back), Vec3(2.f * door, 0.f, 0.f),
                 Vec3(0.f, wall_h - door_h, 0.f), uint32_t(2.f * door * float(density)),
                 uint32_t((wall_h - door_h) * float(density)), relief, [seed](float u, float v) {
                     return 0.004f * value_noise(seed + 2, u * 20.f, v * 30.f) +
                            (std::fabs(v - 0.5f) < 0.3f && std::fabs(u - 0.5f) < 0.4f ? 0.03f : 0.f);
                 });
    // Upper walls, the front wall, the door passage.
    shapes::box(b, Vec3(-hx - 0.5f, wall_h, z_back - 0.5f), Vec3(-hx, roof, z_front), stone);
    shapes::box(b, Vec3(hx, wall_h, z_back - 0.5f), Vec3(hx + 0.5f, roof, z_front), stone);
    shapes::box(b, Vec3(-hx, wall_h, z_back - 0.5f), Vec3(hx, roof, z_back), stone);
    shapes::box(b, Vec3(-hx - 0.5f, 0.f, z_front), Vec3(hx + 0.5f, roof, z_front + 0.5f), stone);
    shapes::box(b, Vec3(-door - 0.3f, 0.f, z_back - 2.5f), Vec3(-door, door_h, z_back), stone);
    shapes::box(b, Vec3(door, 0.f, z_back - 2.5f), Vec3(door + 0.3f, door_h, z_back), stone);
    shapes::box(b, Vec3(-door, door_h, z_back - 2.5f), Vec3(door, door_h + 0.3f, z_back), stone);
    // Columns: papyrus bundles with open capitals, abaci and architraves.
    const uint32_t seg = c.n("column_segments"), rings = c.n("column_rings");
    const float col_h = 8.f;
    const float row_x[4] = {-6.2f, -3.2f, 3.2f, 6.2f};
    const uint32_t per_row = c.n("columns_per_row");
    const float z0 = -15.f, dz = 18.f / float(std::max(1u, per_row - 1));
    for (int r = 0; r < 4; ++r) {
        for (uint32_t k = 0; k < per_row; ++k) {
            const float z = z0 + dz * float(k);
            const uint64_t cs = seed * 977 + uint64_t(r) * 31 + k;
            shapes::lathe(b, Vec3(row_x[r], 0.f, z), col_h, seg, rings, stone,
                          [cs](float theta, float t) {
                              const float lobes = 0.9f + 0.1f * std::fabs(std::cos(4.f * theta));
                              const float wear = 0.015f * value_noise(cs, theta * 6.f, t * 40.f);
                              if (t < 0.03f) return 0.8f - wear;
                              if (t < 0.05f) return 0.8f - 0.25f * smoothstep(0.03f, 0.05f, t) - wear;
                              float r = (0.55f - 0.05f * t) * lobes;
                              if (t > 0.64f && t < 0.71f)  // five tied bands
                                  r += 0.03f * std::fabs(std::sin((t - 0.64f) / 0.07f * 5.f * 3.14159f));
                              if (t >= 0.71f) {
                                  const float open = std::pow(smoothstep(0.71f, 0.96f, t), 0.8f);
                                  r = (0.52f + 0.42f * open) *
                                      (0.94f + 0.06f * std::fabs(std::cos(12.f * theta)));
                              }
                              // Incised bands of decoration on the shaft.
                              const float band = std::fmod(t * 14.f, 1.f);
                              if (t > 0.1f && t < 0.6f && band < 0.08f) r -= 0.01f;
                              return r - wear;
                          });
            shapes::box(b, Vec3(row_x[r] - 0.6f, col_h, z - 0.6f), Vec3(row_x[r] + 0.6f, col_h + 0.4f, z + 0.6f),
                        stone);
        }
        shapes::box(b, Vec3(row_x[r] - 0.5f, col_h + 0.4f, z0 - 1.f),
                    Vec3(row_x[r] + 0.5f, col_h + 1.2f, z0 + dz * float(per_row - 1) + 1.f), stone);
    }
    // Roof slabs, leaving a slot over the central aisle.
    const float slot = 2.2f;
    shapes::box(b, Vec3(-hx, col_h + 1.2f, z_back), Vec3(-slot, roof, z_front), stone);
    shapes::box(b, Vec3(slot, col_h + 1.2f, z_back), Vec3(hx, roof, z_front), stone);
    shapes::box(b, Vec3(-slot, col_h + 1.2f, z_back), Vec3(slot, roof, z0 - 1.f), stone);
    shapes::box(b, Vec3(-slot, col_h + 1.2f, z0 + dz * float(per_row - 1) + 1.f), Vec3(slot, roof, z_front), stone);
    // Seated colossi flanking the sanctuary door.
    const uint32_t statue_levels = c.n("statue_detail");
    for (int s = -1; s <= 1; s += 2) {
        const Vec3 o(2.05f * float(s), 0.f, z_back + 2.2f);
        shapes::box(b, o + Vec3(-1.f, 0.f, -1.9f), o + Vec3(1.f, 0.35f, 0.9f), stone);
        shapes::box(b, o + Vec3(-0.85f, 0.35f, -1.8f), o + Vec3(0.85f, 2.f, 0.f), stone);
        shapes::box(b, o + Vec3(-0.85f, 2.f, -1.8f), o + Vec3(0.85f, 3.6f, -1.35f), stone);
        struct Part { Vec3 c, r; };
        const Part parts[] = {
            {{-0.35f, 1.15f, 0.35f}, {0.24f, 0.85f, 0.27f}}, {{0.35f, 1.15f, 0.35f}, {0.24f, 0.85f, 0.27f}},
            {{-0.35f, 0.47f, 0.62f}, {0.19f, 0.12f, 0.33f}}, {{0.35f, 0.47f, 0.62f}, {0.19f, 0.12f, 0.33f}},
            {{-0.35f, 2.15f, -0.3f}, {0.28f, 0.24f, 0.78f}}, {{0.35f, 2.15f, -0.3f}, {0.28f, 0.24f, 0.78f}},
            {{0.f, 2.95f, -0.95f}, {0.55f, 0.8f, 0.38f}},    {{0.f, 3.65f, -0.95f}, {0.78f, 0.3f, 0.36f}},
            {{0.f, 4.3f, -0.9f}, {0.28f, 0.36f, 0.3f}},      {{0.f, 4.4f, -1.02f}, {0.46f, 0.46f, 0.36f}},
            {{-0.35f, 2.5f, -0.15f}, {0.12f, 0.12f, 0.55f}}, {{0.35f, 2.5f, -0.15f}, {0.12f, 0.12f, 0.55f}},
            {{-0.66f, 3.15f, -0.9f}, {0.16f, 0.5f, 0.17f}},  {{0.66f, 3.15f, -0.9f}, {0.16f, 0.5f, 0.17f}},
        };
        uint64_t k = 0;
        for (const Part& p : parts)
            shapes::rock(b, o + p.c, p.r, statue_levels, seed * 7919 + uint64_t(s + 1) * 100 + k++, 0.06f,
                         stone);
        shapes::lathe(b, o + Vec3(0.f, 4.7f, -0.95f), 0.55f, 48, 12, stone, [](float, float t) {
            return 0.22f - 0.1f * t + 0.04f * std::sin(t * 3.14159f);  // crown
        });
    }
    // Rubble: piles of fallen stones along the walls and around column bases.
    const uint32_t rocks = c.n("rubble_stones");
    const uint32_t rock_levels = c.n("rubble_detail");
    const uint32_t piles = 40;
    b.expect(uint64_t(rocks) * (shapes::icosphere(rock_levels).indices.size() / 3));
    for (uint32_t i = 0; i < rocks; ++i) {
        const uint32_t pile = uint32_t(hash_float(seed, i, 50) * float(piles));
        float px, pz;
        const float side = hash_float(seed, pile, 51) < 0.5f ? -1.f : 1.f;
        if (pile % 2 == 0) {  // against a side wall
            px = side * (hx - 1.1f);
            pz = z_back + 1.f + (len - 3.f) * hash_float(seed, pile, 52);
        } else {  // at the foot of a column of the outer rows
            const uint32_t col = uint32_t(hash_float(seed, pile, 53) * float(per_row));
            px = side * (row_x[3] + 0.9f);
            pz = z0 + dz * float(std::min(col, per_row - 1)) + 0.8f;
        }
        const float a = 6.2832f * hash_float(seed, i, 54);
        const float d = 0.8f * std::sqrt(hash_float(seed, i, 55));
        const float size = 0.04f + 0.3f * std::pow(hash_float(seed, i, 56), 3.f);
        const Vec3 stretch(1.f + 0.6f * hash_float(seed, i, 57), 0.7f, 1.f + 0.6f * hash_float(seed, i, 58));
        shapes::rock(b, Vec3(px + d * std::cos(a), size * 0.45f, pz + d * std::sin(a)), stretch * size,
                     rock_levels, seed * 104729 + i, 0.5f, stone);
    }
    // Lights: the roof slot over the aisle and the glow of the sanctuary.
    b.begin_object();
    shapes::quad(b, Vec3(-slot, roof, z0 - 1.f), Vec3(2.f * slot, 0.f, 0.f),
                 Vec3(0.f, 0.f, dz * float(per_row - 1) + 2.f), c.m("sky"));
    b.begin_object();
    shapes::quad(b, Vec3(-door, 0.f, z_back - 2.4f), Vec3(2.f * door, 0.f, 0.f), Vec3(0.f, door_h, 0.f),
                 c.m("sanctuary"));
    b.begin_object();
}

GeneratorParam P(const char* name, double value, double lo, double hi, bool integer, const char* help) {
    return GeneratorParam{name, value, lo, hi, integer, help};
}

}  // namespace

const std::vector<GeneratorInfo>& generators() {
    static const std::vector<GeneratorInfo> list = {
        {"atrium",
         "two-storey arcaded courtyard under a sky panel, fountain, glass and metal spheres",
         {P("bays", 8, 2, 64, true, "arches per side and storey (3 m each)"),
          P("column_segments", 28, 3, 512, true, "segments around a column"),
          P("column_rings", 15, 1, 512, true, "rings up a column"),
          P("arch_segments", 24, 2, 512, true, "segments along an arch"),
          P("balusters_per_bay", 7, 0, 64, true, "balusters in each upper bay"),
          P("baluster_segments", 12, 3, 256, true, "segments around a baluster"),
          P("baluster_rings", 10, 1, 256, true, "rings up a baluster"),
          P("curtain_resolution", 14, 1, 256, true, "grid cells across a hanging cloth"),
          P("pedestals", 4, 0, 64, true, "pedestals with spheres along each side"),
          P("shrub_detail", 2, 0, 6, true, "icosphere subdivisions of a shrub")},
         {"stone", "floor", "floor_dark", "glass", "metal", "plant", "cloth_red", "cloth_blue",
          "cloth_green", "sky", "lantern"},
         build_atrium},
        {"conference",
         "conference room: long table, office chairs, wainscot, 12 x 6 ceiling light panels",
         {P("chairs_per_side", 10, 0, 64, true, "chairs along each side of the table"),
          P("wall_chairs_per_side", 12, 0, 64, true, "chairs along each long wall"),
          P("chair_detail", 27, 4, 256, true, "grid cells across a chair's seat and back"),
          P("cup_segments", 24, 3, 256, true, "segments around a cup")},
         {"wall", "carpet", "wood", "metal", "ceiling", "whiteboard", "fabric", "fabric_alt",
          "paper", "panel"},
         build_conference},
        {"temple",
         "Egyptian hypostyle hall: papyrus columns, relief walls, colossi, rubble, roof slot",
         {P("relief_density", 25, 1, 400, true, "relief grid cells per metre of wall"),
          P("column_segments", 96, 3, 1024, true, "segments around a column"),
          P("column_rings", 120, 1, 2048, true, "rings up a column"),
          P("columns_per_row", 6, 1, 32, true, "columns in each of the four rows"),
          P("statue_detail", 4, 0, 7, true, "icosphere subdivisions of a statue part"),
          P("rubble_stones", 1950, 0, 1000000, true, "fallen stones"),
          P("rubble_detail", 2, 0, 6, true, "icosphere subdivisions of a stone")},
         {"stone", "relief", "floor", "sky", "sanctuary"},
         build_temple},
    };
    return list;
}

const GeneratorInfo* find_generator(const std::string& name) {
    for (const GeneratorInfo& g : generators())
        if (g.name == name) return &g;
    return nullptr;
}

}  // namespace sfx
