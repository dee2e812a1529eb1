// Shape helpers (generators.h, namespace shapes): quads, boxes, grids, lathes, arches,
// parametric patches and rocks, appended to a SceneBuilder's current object.

#include <algorithm>
#include <cmath>
#include <map>
#include <mutex>
#include <utility>

#include "workloads/generator_kit.h"

namespace sfx {

// ---- shapes -------------------------------------------------------------------------------

namespace shapes {

namespace {
Vec3 place(const Transform* xf, const Vec3& p) {
    return xf ? xf->apply(p) : p;
}
// Two triangles per cell of an (nu + 1) x (nv + 1) vertex grid appended from `first`, row by row.
void grid_triangles(SceneBuilder& b, uint32_t first, uint32_t nu, uint32_t nv, uint32_t material) {
    const uint32_t row = nu + 1;
    for (uint32_t j = 0; j < nv; ++j)
        for (uint32_t i = 0; i < nu; ++i) {
            const uint32_t a = first + j * row + i;
            b.add_triangle(a, a + 1, a + row + 1, material);
            b.add_triangle(a, a + row + 1, a + row, material);
        }
}
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
        v[i] = b.add_vertex(
            place(xf, Vec3(i & 1 ? hi.x : lo.x, i & 2 ? hi.y : lo.y, i & 4 ? hi.z : lo.z)));
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
    grid_triangles(b, first, nu, nv, material);
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
        for (uint32_t i = 0; i <= nu; ++i)
            b.add_vertex(point(float(i) / float(nu), float(j) / float(nv)));
    grid_triangles(b, first, nu, nv, material);
}

const IcoMesh& icosphere(uint32_t levels) {
    // Built once per level and shared; std::map nodes never move, so references stay valid.
    static std::mutex mutex;
    static std::map<uint32_t, IcoMesh> cache;
    std::lock_guard<std::mutex> lock(mutex);
    auto found = cache.find(levels);
    if (found != cache.end()) return found->second;
    IcoMesh m;
    const float t = (1.f + std::sqrt(5.f)) * 0.5f;
    const Vec3 v[12] = {{-1, t, 0},  {1, t, 0},  {-1, -t, 0}, {1, -t, 0}, {0, -1, t},  {0, 1, t},
                        {0, -1, -t}, {0, 1, -t}, {t, 0, -1},  {t, 0, 1},  {-t, 0, -1}, {-t, 0, 1}};
    for (const Vec3& p : v) m.vertices.push_back(normalize(p));
    m.indices = {0, 11, 5,  0, 5,  1, 0, 1, 7, 0, 7,  10, 0, 10, 11, 1, 5, 9, 5, 11,
                 4, 11, 10, 2, 10, 7, 6, 7, 1, 8, 3,  9,  4, 3,  4,  2, 3, 2, 6, 3,
                 6, 8,  3,  8, 9,  4, 9, 5, 2, 4, 11, 6,  2, 10, 8,  6, 7, 9, 8, 1};
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
        for (int k = 0; k < 4; ++k)
            r += roughness * 0.25f * std::sin(freq[k] * dot(n, dirs[k]) + phase[k]);
        b.add_vertex(center + n * size * r);
    }
    for (size_t i = 0; i < ico.indices.size(); i += 3)
        b.add_triangle(first + ico.indices[i], first + ico.indices[i + 1],
                       first + ico.indices[i + 2], material);
}

}  // namespace shapes

}  // namespace sfx
