// The BVH: a deterministic build, and traversal that returns exactly the brute-force closest
// hit (same primitive and bits, equal-t ties to the lower id) whatever the tree looks like.

#include <catch2/catch.hpp>

#include "tests/kernels/geometry_test_util.h"

using namespace sfx;
using namespace sfx::test;

namespace {

// A random soup of triangles and spheres, plus structures that produce equal-t ties:
// duplicated triangles and spheres, axis-aligned coplanar overlapping triangles, and
// triangles sharing edges.
Scene soup(uint32_t seed) {
    TestRng rng(seed);
    Scene s;
    add_material(s);
    for (int i = 0; i < 2000; ++i) {
        const Vec3 c(rng.range(-10.f, 10.f), rng.range(-10.f, 10.f), rng.range(-10.f, 10.f));
        const float size = std::pow(10.f, rng.range(-2.f, 0.5f));
        add_triangle(s, c + rng.unit_vector() * size, c + rng.unit_vector() * size,
                     c + rng.unit_vector() * size);
    }
    // Coplanar overlapping squares on planes x, y or z = k / 2 (exact t for axis rays).
    for (int i = 0; i < 300; ++i) {
        const int axis = int(rng.below(3));
        const float k = float(int(rng.below(41)) - 20) * 0.5f;
        const float u0 = float(int(rng.below(33)) - 16) * 0.5f;
        const float v0 = float(int(rng.below(33)) - 16) * 0.5f;
        const float w = float(1 + rng.below(6)) * 0.5f;
        auto pt = [&](float u, float v) {
            Vec3 p;
            p[axis] = k;
            p[(axis + 1) % 3] = u;
            p[(axis + 2) % 3] = v;
            return p;
        };
        const uint32_t a = add_vertex(s, pt(u0, v0)), b = add_vertex(s, pt(u0 + w, v0)),
                       c = add_vertex(s, pt(u0 + w, v0 + w)), d = add_vertex(s, pt(u0, v0 + w));
        add_triangle(s, a, b, c);  // shared edge a-c
        add_triangle(s, a, c, d);
    }
    // Exact duplicates (same vertex indices) at shuffled ids.
    const uint32_t base = s.triangle_count();
    for (uint32_t i = 0; i < 200; ++i) {
        const Triangle t = s.triangles[rng.below(base)];
        s.triangles.push_back(t);
    }
    for (int i = 0; i < 300; ++i) {
        Sphere sp;
        sp.center = Vec3(rng.range(-10.f, 10.f), rng.range(-10.f, 10.f), rng.range(-10.f, 10.f));
        sp.radius = std::pow(10.f, rng.range(-2.f, 0.f));
        s.spheres.push_back(sp);
        if (i % 10 == 0) s.spheres.push_back(sp);
    }
    return s;
}

std::vector<Ray> soup_rays(uint32_t seed, int count) {
    TestRng rng(seed);
    std::vector<Ray> rays;
    for (int i = 0; i < count; ++i) {
        Ray r;
        r.org = Vec3(rng.range(-12.f, 12.f), rng.range(-12.f, 12.f), rng.range(-12.f, 12.f));
        switch (i % 4) {
            case 0:
                r.dir = rng.unit_vector();
                break;
            case 1: {  // along an axis from a half-integer grid: hits the coplanar squares
                const int axis = int(rng.below(3));
                r.dir = Vec3(0.f);
                r.dir[axis] = rng.uniform() < 0.5f ? -1.f : 1.f;
                for (int a = 0; a < 3; ++a) {
                    r.org[a] = std::round(r.org[a] * 4.f) / 4.f;  // often exactly on edges
                    if (a == axis) r.org[a] = r.dir[a] < 0.f ? 12.f : -12.f;
                }
                break;
            }
            case 2: {  // aimed at the origin of a cluster, unnormalized
                const Vec3 target(rng.range(-10.f, 10.f), rng.range(-10.f, 10.f),
                                  rng.range(-10.f, 10.f));
                r.dir = target - r.org;
                break;
            }
            default:
                r.dir = rng.unit_vector() * rng.range(0.01f, 100.f);
                break;
        }
        if (i % 3 == 0) r.t_max = rng.range(0.5f, 20.f);
        rays.push_back(r);
    }
    return rays;
}

bool same_nodes(const Bvh& a, const Bvh& b) {
    if (a.nodes().size() != b.nodes().size() || a.prim_ids() != b.prim_ids()) return false;
    for (size_t i = 0; i < a.nodes().size(); ++i) {
        const BvhNode &x = a.nodes()[i], &y = b.nodes()[i];
        for (int k = 0; k < 3; ++k)
            if (!same_bits(x.bounds.lo[k], y.bounds.lo[k]) ||
                !same_bits(x.bounds.hi[k], y.bounds.hi[k]))
                return false;
        if (x.first != y.first || x.count != y.count || x.axis != y.axis)
            return false;
    }
    return true;
}

}  // namespace

TEST_CASE("geometry: BVH build is deterministic", "[geometry]") {
    const Scene s = [] {
        Scene x = soup(21);
        x.finalize();
        return x;
    }();
    for (const BvhBuildOptions& options :
         {BvhBuildOptions{}, BvhBuildOptions{1, 8, 1.f, 1.f}, BvhBuildOptions{8, 32, 2.f, 1.f}}) {
        const Bvh a(s, options), b(s, options);
        CHECK(same_nodes(a, b));
        CHECK(a.stats().sah_cost == b.stats().sah_cost);
        // Every primitive appears exactly once; leaves respect the size limit where SAH allows.
        std::vector<uint32_t> ids = a.prim_ids();
        std::sort(ids.begin(), ids.end());
        for (uint32_t i = 0; i < ids.size(); ++i) REQUIRE(ids[i] == i);
    }
    // A copy of the scene (different addresses) builds the same tree.
    const Scene copy = s;
    CHECK(same_nodes(Bvh(s), Bvh(copy)));
}

TEST_CASE("geometry: BVH traversal equals brute force, ties included", "[geometry]") {
    auto world = make_world(soup(22));
    const std::vector<Ray> rays = soup_rays(23, 6000);
    std::vector<std::unique_ptr<Bvh>> trees;
    trees.push_back(std::make_unique<Bvh>(world->scene, BvhBuildOptions{1, 16, 1.f, 1.f}));
    trees.push_back(std::make_unique<Bvh>(world->scene, BvhBuildOptions{8, 4, 1.f, 3.f}));
    int hits = 0, ties = 0, mismatches = 0, occlusion_mismatches = 0;
    for (const Ray& ray : rays) {
        const Hit reference = brute_force(world->bvh, ray);
        hits += reference.valid();
        if (reference.valid()) {
            // Count rays on which another primitive reports the very same t.
            const RayPrecomp r(ray);
            for (uint32_t p = 0; p < world->scene.primitive_count(); ++p) {
                Hit h;
                if (p != reference.prim && world->bvh.intersect_primitive(r, p, ray.t_max, h) &&
                    h.t == reference.t) {
                    ++ties;
                    break;
                }
            }
        }
        auto check = [&](const Bvh& bvh) {
            const Hit hit = bvh.intersect(ray);
            const bool same = hit.prim == reference.prim && same_bits(hit.t, reference.t) &&
                              same_bits(hit.u, reference.u) && same_bits(hit.v, reference.v);
            if (!same) {
                ++mismatches;
                UNSCOPED_INFO("ray " << ray.org.x << ' ' << ray.org.y << ' ' << ray.org.z << " / "
                                     << ray.dir.x << ' ' << ray.dir.y << ' ' << ray.dir.z << " bvh "
                                     << hit.prim << " t " << hit.t << " ref " << reference.prim
                                     << " t " << reference.t);
            }
            occlusion_mismatches += bvh.occluded(ray) != reference.valid();
        };
        check(world->bvh);
        for (const auto& tree : trees) check(*tree);
    }
    CHECK(mismatches == 0);
    CHECK(occlusion_mismatches == 0);
    CHECK(hits > 2000);
    CHECK(ties > 200);
}
