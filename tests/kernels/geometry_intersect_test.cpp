// Hard cases of the single-primitive tests (issue 2, cases 5-10 and 13): axis-aligned and
// signed-zero directions, denormals, zero/NaN/Inf rays, degenerate triangles, exact hits,
// back faces and coplanar ties.

#include <catch2/catch.hpp>
#include <cfloat>
#include <limits>

#include "tests/kernels/geometry_test_util.h"

using namespace sfx;
using namespace sfx::test;

namespace {

// Axis-aligned cube [-1, 1]^3 as 12 triangles with shared vertices.
Scene cube_scene() {
    Scene s;
    add_material(s);
    for (int i = 0; i < 8; ++i)
        add_vertex(s, Vec3(i & 1 ? 1.f : -1.f, i & 2 ? 1.f : -1.f, i & 4 ? 1.f : -1.f));
    const uint32_t faces[6][4] = {{0, 2, 6, 4}, {1, 5, 7, 3}, {0, 4, 5, 1},
                                  {2, 3, 7, 6}, {0, 1, 3, 2}, {4, 6, 7, 5}};
    for (const auto& f : faces) {
        add_triangle(s, f[0], f[1], f[2]);
        add_triangle(s, f[0], f[2], f[3]);
    }
    return s;
}

bool same_hit(const Hit& a, const Hit& b) {
    return a.prim == b.prim && same_bits(a.t, b.t) && same_bits(a.u, b.u) && same_bits(a.v, b.v);
}

}  // namespace

TEST_CASE("geometry: axis-aligned directions and signed zeros give no NaN and the right hit",
          "[geometry]") {
    const Bounds3 box{Vec3(-1.f), Vec3(1.f)};
    const float others[] = {-1.f, 1.f, 0.f, 0.5f, -0.f, -2.f, 1.0000001f, 3.f};
    auto world = make_world(cube_scene());
    int hits = 0;
    for (int axis = 0; axis < 3; ++axis)
        for (float sign : {1.f, -1.f})
            for (int zeros = 0; zeros < 4; ++zeros)
                for (float o1 : others)
                    for (float o2 : others) {
                        const int a1 = (axis + 1) % 3, a2 = (axis + 2) % 3;
                        Ray ray;
                        ray.org[axis] = -3.f * sign;
                        ray.org[a1] = o1;
                        ray.org[a2] = o2;
                        ray.dir[axis] = sign;
                        ray.dir[a1] = zeros & 1 ? -0.f : 0.f;
                        ray.dir[a2] = zeros & 2 ? -0.f : 0.f;
                        const bool inside = std::fabs(o1) <= 1.f && std::fabs(o2) <= 1.f;
                        const float t = intersect_box(RayPrecomp(ray), box, INFINITY);
                        CAPTURE(axis, sign, zeros, o1, o2);
                        REQUIRE_FALSE(std::isnan(t));
                        CHECK(t == (inside ? 2.f : INFINITY));
                        // Origin inside the box: entry at 0.
                        Ray inner = ray;
                        inner.org[axis] = 0.25f;
                        const float t_in = intersect_box(RayPrecomp(inner), box, INFINITY);
                        REQUIRE_FALSE(std::isnan(t_in));
                        CHECK(t_in == (inside ? 0.f : INFINITY));
                        // The cube mesh: the face on the far side of x = -3 is hit at exactly 2,
                        // including rays gliding along a face (on its boundary edge).
                        const Hit hit = world->bvh.intersect(ray);
                        CHECK(hit.valid() == inside);
                        if (inside) {
                            ++hits;
                            CHECK(hit.t == 2.f);
                            Ray plus = ray;
                            plus.dir[a1] = 0.f;
                            plus.dir[a2] = 0.f;
                            CHECK(same_hit(hit, world->bvh.intersect(plus)));
                            CHECK(same_hit(hit, brute_force(world->bvh, ray)));
                        }
                        CHECK(world->bvh.occluded(ray) == inside);
                    }
    CHECK(hits > 100);
}

TEST_CASE("geometry: denormal direction components behave exactly like zeros", "[geometry]") {
    auto world = make_world(cube_scene());
    TestRng rng(6);
    const float denormals[] = {1e-40f, -1e-40f, FLT_TRUE_MIN, -FLT_TRUE_MIN, 1.1e-38f, -5e-39f};
    for (int i = 0; i < 2000; ++i) {
        Ray zero;
        const int axis = int(rng.below(3));
        zero.org = Vec3(rng.range(-1.2f, 1.2f), rng.range(-1.2f, 1.2f), rng.range(-1.2f, 1.2f));
        zero.org[axis] = rng.uniform() < 0.5f ? -4.f : rng.range(-0.9f, 0.9f);
        zero.dir[axis] = rng.uniform() < 0.5f ? -1.f : 1.f;
        Ray denormal = zero;
        for (int a = 0; a < 3; ++a) {
            if (a == axis) continue;
            if (rng.uniform() < 0.2f) continue;  // leave some exact zeros
            denormal.dir[a] = denormals[rng.below(6)];
            zero.dir[a] = std::copysign(0.f, denormal.dir[a]);
        }
        CAPTURE(i, denormal.org.x, denormal.org.y, denormal.org.z, denormal.dir.x, denormal.dir.y,
                denormal.dir.z);
        const Hit hz = world->bvh.intersect(zero), hd = world->bvh.intersect(denormal);
        REQUIRE(same_hit(hz, hd));
        REQUIRE(world->bvh.occluded(zero) == world->bvh.occluded(denormal));
    }
    // A direction made only of denormals is a zero direction: inactive.
    Ray tiny;
    tiny.org = Vec3(0.f);
    tiny.dir = Vec3(1e-40f, -1e-41f, FLT_TRUE_MIN);
    CHECK_FALSE(ray_is_valid(tiny));
    CHECK_FALSE(world->bvh.intersect(tiny).valid());
    CHECK_FALSE(world->bvh.occluded(tiny));
}

TEST_CASE("geometry: zero direction misses without hanging", "[geometry]") {
    auto world = make_world(cube_scene());
    for (const Vec3 org : {Vec3(0.f), Vec3(1.f, 0.f, 0.f), Vec3(1.f, 1.f, 1.f), Vec3(5.f)}) {
        for (const Vec3 dir : {Vec3(0.f), Vec3(-0.f, 0.f, -0.f), Vec3(-0.f)}) {
            const Ray ray{org, dir, INFINITY};
            CHECK_FALSE(ray_is_valid(ray));
            CHECK_FALSE(world->bvh.intersect(ray).valid());
            CHECK_FALSE(world->bvh.occluded(ray));
        }
    }
}

TEST_CASE("geometry: NaN or Inf rays are inactive and miss", "[geometry]") {
    Scene s = cube_scene();
    Sphere sp;
    sp.center = Vec3(0.f);
    sp.radius = 3.f;
    s.spheres.push_back(sp);
    auto world = make_world(std::move(s));
    const float bad[] = {std::numeric_limits<float>::quiet_NaN(), INFINITY, -INFINITY,
                         -std::numeric_limits<float>::quiet_NaN()};
    int cases = 0;
    for (float b : bad)
        for (int which = 0; which < 6; ++which) {
            Ray ray{Vec3(0.1f, 0.2f, -5.f), Vec3(0.f, 0.f, 1.f), INFINITY};
            if (which < 3)
                ray.org[which] = b;
            else
                ray.dir[which - 3] = b;
            CAPTURE(b, which);
            CHECK_FALSE(ray_is_valid(ray));
            CHECK_FALSE(world->bvh.intersect(ray).valid());
            CHECK_FALSE(world->bvh.occluded(ray));
            ++cases;
        }
    for (float t_max : {std::numeric_limits<float>::quiet_NaN(), -1.f, 0.f, -0.f, -INFINITY}) {
        const Ray ray{Vec3(0.1f, 0.2f, -5.f), Vec3(0.f, 0.f, 1.f), t_max};
        CAPTURE(t_max);
        CHECK_FALSE(ray_is_valid(ray));
        CHECK_FALSE(world->bvh.intersect(ray).valid());
        CHECK_FALSE(world->bvh.occluded(ray));
    }
    CHECK(cases == 24);
}

TEST_CASE("geometry: degenerate triangles are never hit", "[geometry]") {
    TestRng rng(9);
    Scene s;
    std::vector<Vec3> targets;  // points on the degenerate triangles
    auto dyadic = [&](int range, float scale) {
        return Vec3(float(int(rng.below(2 * range + 1)) - range) * scale,
                    float(int(rng.below(2 * range + 1)) - range) * scale,
                    float(int(rng.below(2 * range + 1)) - range) * scale);
    };
    for (int i = 0; i < 300; ++i) {
        const float scale = i % 3 == 0 ? 1.f / 1024.f : (i % 3 == 1 ? 1.f : 64.f);
        const Vec3 p = dyadic(4096, scale);
        Vec3 d = dyadic(256, scale);
        if (is_black(d)) d = Vec3(scale, 0.f, 0.f);
        switch (i % 5) {
            case 0:
                add_triangle(s, p, p, p);
                targets.push_back(p);
                break;  // a point
            case 1:
                add_triangle(s, p, p + d, p);
                break;  // two equal vertices
            case 2:
                add_triangle(s, p, p + d, p + d * 2.f);
                break;  // collinear
            case 3:
                add_triangle(s, p + d * 2.f, p, p + d * 3.f);
                break;  // collinear, middle first
            case 4:
                add_triangle(s, p, p + d * 4.f, p + d);
                break;
        }
        if (i % 5 != 0) {
            targets.push_back(p + d * 0.5f);
            targets.push_back(p + d);
            targets.push_back(p);
        }
    }
    // Exactly collinear triangles far from the origin.
    for (int i = 0; i < 60; ++i) {
        const Vec3 p = Vec3(1048576.f) + dyadic(65536, 1.f);
        const Vec3 d = dyadic(64, 1.f) + Vec3(1.f, 0.f, 0.f);
        add_triangle(s, p, p + d, p + d * 2.f);
        targets.push_back(p + d);
        targets.push_back(p + d * 0.5f);
    }
    auto world = make_world(std::move(s));
    const uint32_t n = world->scene.primitive_count();
    int rays = 0;
    auto check_ray = [&](const Ray& ray) {
        ++rays;
        const RayPrecomp r(ray);
        for (uint32_t p = 0; p < n; ++p) {
            Hit hit;
            if (world->bvh.intersect_primitive(r, p, ray.t_max, hit)) {
                CAPTURE(p, ray.org.x, ray.org.y, ray.org.z, ray.dir.x, ray.dir.y, ray.dir.z);
                FAIL("degenerate triangle hit");
            }
        }
        CHECK_FALSE(world->bvh.intersect(ray).valid());
        CHECK_FALSE(world->bvh.occluded(ray));
    };
    for (const Vec3& target : targets)
        for (int k = 0; k < 8; ++k) {
            const float dist = k < 4 ? 3.f : 3000.f;
            const Vec3 org = target + rng.unit_vector() * dist;
            check_ray(Ray{org, target - org, INFINITY});
        }
    // Rays running along the line of each degenerate triangle.
    for (uint32_t p = 0; p < n; ++p) {
        const Triangle& tri = world->scene.triangles[p];
        const Vec3 a = world->scene.positions[tri.v0], b = world->scene.positions[tri.v1];
        const Vec3 d = a == b ? world->scene.positions[tri.v2] - a : b - a;
        if (is_black(d)) continue;
        check_ray(Ray{a - d * 2.f, d, INFINITY});
        check_ray(Ray{a + d * 8.f, -d, INFINITY});
    }
    CHECK(rays > 2500);
}

TEST_CASE("geometry: exact hit on a unit triangle within 16 ulp", "[geometry]") {
    Scene s;
    add_triangle(s, Vec3(0.f, 0.f, 0.f), Vec3(1.f, 0.f, 0.f), Vec3(0.f, 1.f, 0.f));
    auto world = make_world(std::move(s));
    const Vec3 org(0.f, 0.f, -1.f);
    TestRng rng(10);
    int checked = 0;
    for (int i = 0; i < 4000; ++i) {
        // Interior targets: a dyadic grid first, then random points.
        float x, y;
        if (i < 1891) {  // all (i, j) / 64 with i, j >= 1 and i + j <= 63
            int k = i, a = 1;
            while (k >= 63 - a) {
                k -= 63 - a;
                ++a;
            }
            x = float(a) / 64.f;
            y = float(k + 1) / 64.f;
        } else {
            x = rng.range(1e-3f, 0.998f);
            y = rng.range(1e-3f, 0.999f - x);
        }
        const Vec3 target(x, y, 0.f);
        for (bool unit : {false, true}) {
            Ray ray{org, target - org, INFINITY};
            double expected_t = 1.0;
            if (unit) {
                ray.dir = normalize(ray.dir);
                // The ray actually traced is org + t dir with the rounded unit direction.
                expected_t = 1.0 / double(ray.dir.z);
            }
            const Hit hit = world->bvh.intersect(ray);
            CAPTURE(x, y, unit, hit.t, hit.u, hit.v);
            REQUIRE(hit.valid());
            const double hx = double(ray.dir.x) * expected_t, hy = double(ray.dir.y) * expected_t;
            CHECK(within_ulps(hit.t, float(expected_t)));
            CHECK(within_ulps(hit.u, float(hx)));
            CHECK(within_ulps(hit.v, float(hy)));
            const SurfaceHit sh = surface_at(world->scene, ray, hit);
            CHECK(sh.front_face == false);  // the stored normal (0, 0, 1) faces away from the ray
            CHECK(within_ulps(sh.normal.x, 0.f));
            CHECK(within_ulps(sh.normal.y, 0.f));
            CHECK(within_ulps(sh.normal.z, -1.f));
            CHECK(within_ulps(sh.position.x, float(hx)));
            CHECK(within_ulps(sh.position.y, float(hy)));
            CHECK(within_ulps(sh.position.z, 0.f));
            ++checked;
        }
    }
    CHECK(checked == 8000);
}

TEST_CASE("geometry: back faces are hit and coplanar overlaps tie-break by id", "[geometry]") {
    SECTION("back faces of triangles and spheres") {
        Scene s;
        add_triangle(s, Vec3(-1.f, -1.f, 0.f), Vec3(1.f, -1.f, 0.f), Vec3(0.f, 1.f, 0.f));
        Sphere sp;
        sp.center = Vec3(10.f, 0.f, 0.f);
        sp.radius = 2.f;
        s.spheres.push_back(sp);
        auto world = make_world(std::move(s));
        for (float side : {1.f, -1.f}) {
            const Ray ray{Vec3(0.1f, 0.f, 3.f * side), Vec3(0.f, 0.f, -side), INFINITY};
            const Hit hit = world->bvh.intersect(ray);
            REQUIRE(hit.prim == 0);
            CHECK(hit.t == 3.f);
            const SurfaceHit sh = surface_at(world->scene, ray, hit);
            CHECK(sh.front_face == (side > 0.f));
            CHECK(sh.normal.z == side);  // faces the incoming ray either way
        }
        // From inside the sphere: the back face is hit at the radius.
        const Ray inner{Vec3(10.f, 0.f, 0.f), Vec3(0.f, 1.f, 0.f), INFINITY};
        const Hit hit = world->bvh.intersect(inner);
        REQUIRE(hit.prim == 1);
        CHECK(within_ulps(hit.t, 2.f));
        const SurfaceHit sh = surface_at(world->scene, inner, hit);
        CHECK_FALSE(sh.front_face);
        CHECK(sh.normal.y < -0.999f);
    }
    SECTION("coplanar overlapping triangles and duplicates: lower id wins on equal t") {
        TestRng rng(13);
        // Plane z = 1 (exact t = 1 for rays from z = 0 with dir.z = 1) and a tilted plane.
        const Vec3 a0(-1.f, -1.f, 1.f), a1(1.f, -1.f, 1.f), a2(0.f, 1.f, 1.f);
        const Vec3 b0(-0.5f, 1.f, 1.f), b1(0.f, -1.f, 1.f), b2(1.f, 1.f, 1.f);
        for (int order = 0; order < 2; ++order) {
            Scene s;
            if (order == 0) {
                add_triangle(s, a0, a1, a2);
                add_triangle(s, b0, b1, b2);
            } else {
                add_triangle(s, b0, b1, b2);
                add_triangle(s, a0, a1, a2);
            }
            // Exact duplicates of the first triangle and of a sphere.
            add_triangle(s, s.triangles[0].v0, s.triangles[0].v1, s.triangles[0].v2);
            Sphere sp;
            sp.center = Vec3(0.f, 0.f, 5.f);
            sp.radius = 0.5f;
            s.spheres.push_back(sp);
            s.spheres.push_back(sp);
            auto world = make_world(std::move(s), BvhBuildOptions{1, 16, 1.f, 1.f});
            for (int i = 0; i < 500; ++i) {
                const Vec3 target(rng.range(-0.2f, 0.2f), rng.range(-0.2f, 0.2f), 1.f);
                const Ray ray{Vec3(target.x * 0.5f, target.y * 0.5f, 0.f),
                              Vec3(target.x * 0.5f, target.y * 0.5f, 1.f), INFINITY};
                const Hit hit = world->bvh.intersect(ray);
                REQUIRE(hit.valid());
                CHECK(hit.t == 1.f);
                CHECK(hit.prim == 0);  // both overlapping triangles and the duplicate tie
                CHECK(same_hit(hit, brute_force(world->bvh, ray)));
                const Ray up{Vec3(target.x, target.y, 3.f), Vec3(0.f, 0.f, 1.f), INFINITY};
                const Hit hs = world->bvh.intersect(up);
                REQUIRE(hs.valid());
                CHECK(hs.prim == 3);  // the first of the two identical spheres
            }
        }
    }
    SECTION("tilted coplanar overlaps: one deterministic winner in any insertion order") {
        TestRng rng(131);
        // Vertices exactly on the plane x + 2y + 4z = 4 (dyadic coordinates).
        auto on_plane = [](float x, float y) { return Vec3(x, y, (4.f - x - 2.f * y) / 4.f); };
        const Vec3 tri[2][3] = {{on_plane(-2.f, -2.f), on_plane(2.f, -2.f), on_plane(0.f, 2.f)},
                                {on_plane(-1.f, 1.5f), on_plane(0.5f, -2.f), on_plane(2.f, 1.5f)}};
        for (int i = 0; i < 300; ++i) {
            const Vec3 target = on_plane(rng.range(-0.3f, 0.3f), rng.range(-0.3f, 0.3f));
            const Vec3 org = target + rng.hemisphere(normalize(Vec3(1.f, 2.f, 4.f)), 0.2f) * 5.f;
            const Ray ray{org, target - org, INFINITY};
            Hit first[2];
            for (int order = 0; order < 2; ++order) {
                Scene s;
                add_triangle(s, tri[order][0], tri[order][1], tri[order][2]);
                add_triangle(s, tri[1 - order][0], tri[1 - order][1], tri[1 - order][2]);
                auto world = make_world(std::move(s), BvhBuildOptions{1, 16, 1.f, 1.f});
                const Hit hit = world->bvh.intersect(ray);
                REQUIRE(hit.valid());
                CHECK(same_hit(hit, brute_force(world->bvh, ray)));
                CHECK(same_hit(hit, world->bvh.intersect(ray)));  // repeatable
                first[order] = hit;
            }
            // Same t bits either way; on a tie the lower id, else the same geometric triangle.
            CHECK(same_bits(first[0].t, first[1].t));
            const uint32_t tri0 = first[0].prim, tri1 = 1 - first[1].prim;
            Scene probe;
            add_triangle(probe, tri[0][0], tri[0][1], tri[0][2]);
            add_triangle(probe, tri[1][0], tri[1][1], tri[1][2]);
            auto pw = make_world(std::move(probe));
            Hit h0, h1;
            const bool hit0 = pw->bvh.intersect_primitive(RayPrecomp(ray), 0, INFINITY, h0);
            const bool hit1 = pw->bvh.intersect_primitive(RayPrecomp(ray), 1, INFINITY, h1);
            if (hit0 && hit1 && h0.t == h1.t) {
                CHECK(first[0].prim == 0);
                CHECK(first[1].prim == 0);
            } else {
                CHECK(tri0 == tri1);
            }
        }
    }
}
