// sfx's BVH against Embree 3: a small scene agrees, shared edges are explained, bad rays never
// reach Embree, and a deliberately wrong Embree scene is caught.

#include "kernels/embree/embree_check.h"

#include <catch2/catch.hpp>
#include <cmath>

#include "kernels/bvh.h"
#include "kernels/sampling.h"

using namespace sfx;

namespace {

// A (cells x cells) grid of quads, two triangles each, spanning corner + [0,1]*a + [0,1]*b.
// Diagonals alternate so edges meet at vertices of valence 4 and 8.
void add_grid(Scene& s, const Vec3& corner, const Vec3& a, const Vec3& b, int cells) {
    const uint32_t base = uint32_t(s.positions.size());
    for (int j = 0; j <= cells; ++j)
        for (int i = 0; i <= cells; ++i)
            s.positions.push_back(corner + a * (float(i) / cells) + b * (float(j) / cells));
    auto at = [&](int i, int j) { return base + uint32_t(j * (cells + 1) + i); };
    for (int j = 0; j < cells; ++j)
        for (int i = 0; i < cells; ++i) {
            const uint32_t p00 = at(i, j), p10 = at(i + 1, j), p01 = at(i, j + 1),
                           p11 = at(i + 1, j + 1);
            if ((i + j) % 2 == 0) {
                s.triangles.push_back({p00, p10, p11, 0});
                s.triangles.push_back({p00, p11, p01, 0});
            } else {
                s.triangles.push_back({p00, p10, p01, 0});
                s.triangles.push_back({p10, p11, p01, 0});
            }
        }
}

// The six faces of the box center +- half, rotated about y by `degrees`.
void add_box(Scene& s, const Vec3& center, const Vec3& half, float degrees, int cells) {
    const float c = std::cos(degrees * k_pi / 180.f), sn = std::sin(degrees * k_pi / 180.f);
    auto rot = [&](const Vec3& v) { return Vec3(c * v.x + sn * v.z, v.y, -sn * v.x + c * v.z); };
    const Vec3 ex = rot({2.f * half.x, 0.f, 0.f}), ey = {0.f, 2.f * half.y, 0.f},
               ez = rot({0.f, 0.f, 2.f * half.z});
    const Vec3 lo = center - rot({half.x, 0.f, half.z}) - Vec3(0.f, half.y, 0.f);
    add_grid(s, lo, ex, ey, cells);
    add_grid(s, lo + ez, ex, ey, cells);
    add_grid(s, lo, ez, ey, cells);
    add_grid(s, lo + ex, ez, ey, cells);
    add_grid(s, lo, ex, ez, cells);
    add_grid(s, lo + ey, ex, ez, cells);
}

// A closed room (6x6 cells per wall), two boxes inside and three spheres: 528 triangles.
Scene make_room(const Vec3& shift = Vec3(0.f)) {
    Scene s;
    s.name = "embree_room";
    s.materials.push_back(Material{});
    add_box(s, shift, Vec3(1.f), 0.f, 6);
    add_box(s, shift + Vec3(-0.4f, -0.6f, -0.3f), Vec3(0.25f, 0.4f, 0.25f), 30.f, 2);
    add_box(s, shift + Vec3(0.45f, -0.8f, 0.1f), Vec3(0.2f, 0.2f, 0.2f), -15.f, 2);
    s.spheres.push_back({shift + Vec3(0.4f, -0.25f, -0.4f), 0.3f, 0});
    s.spheres.push_back({shift + Vec3(-0.5f, 0.4f, 0.2f), 0.2f, 0});
    s.spheres.push_back({shift + Vec3(0.1f, 0.5f, -0.6f), 0.05f, 0});
    s.camera.eye = shift + Vec3(0.f, 0.f, 0.9f);
    s.camera.look_at = shift + Vec3(0.f, -0.2f, -1.f);
    s.camera.vertical_fov_degrees = 70.f;
    return s;
}

EmbreeCheckOptions small_options(uint64_t rays) {
    EmbreeCheckOptions o;
    o.rays = rays;
    o.width = 64;
    o.height = 64;
    o.seed = 7;
    o.threads = 2;
    return o;
}

}  // namespace

TEST_CASE("A tessellated room with boxes and spheres agrees with Embree", "[embree]") {
    const Scene scene = make_room();
    REQUIRE(scene.triangle_count() == 528);
    const Bvh bvh(scene);
    const EmbreeAgreement a = check_against_embree(scene, bvh, small_options(1000000));
    const ClassCounts total = a.total();
    INFO("agree " << total.by_class[size_t(HitClass::agree)] << " tie "
                  << total.by_class[size_t(HitClass::tie)] << " edge "
                  << total.by_class[size_t(HitClass::edge)] << " unexplained "
                  << total.unexplained());
    for (const HitMismatch& m : a.examples) UNSCOPED_INFO(describe(m));
    CHECK(total.traced() == 1000000);
    CHECK(total.filtered == 0);
    CHECK(a.by_kind[size_t(CheckRayKind::primary)].traced() == 500000);
    CHECK(a.by_kind[size_t(CheckRayKind::diffuse)].traced() == 500000);
    CHECK(a.excluded_primitives == 0);
    CHECK(total.unexplained() == 0);
    CHECK(a.examples.empty());
    CHECK(a.pass());
    // The room is closed: every ray hits, and nearly all hit the same primitive at the same t.
    CHECK(total.by_class[size_t(HitClass::both_miss)] == 0);
    CHECK(total.by_class[size_t(HitClass::agree)] > 995000);
}

TEST_CASE("The Embree check does not depend on the thread count", "[embree]") {
    const Scene scene = make_room();
    const Bvh bvh(scene);
    EmbreeCheckOptions one = small_options(40000), two = small_options(40000);
    one.threads = 1;
    two.threads = 3;
    const EmbreeAgreement a = check_against_embree(scene, bvh, one);
    const EmbreeAgreement b = check_against_embree(scene, bvh, two);
    for (size_t k = 0; k < a.by_kind.size(); ++k) {
        CHECK(a.by_kind[k].by_class == b.by_kind[k].by_class);
        CHECK(a.by_kind[k].filtered == b.by_kind[k].filtered);
    }
}

TEST_CASE("A room far from the origin agrees with Embree (robust mode)", "[embree]") {
    const Scene scene = make_room(Vec3(3000.f, -2000.f, 5000.f));
    const Bvh bvh(scene);
    const EmbreeAgreement a = check_against_embree(scene, bvh, small_options(100000));
    INFO("unexplained " << a.total().unexplained() << " of " << a.total().traced());
    for (const HitMismatch& m : a.examples) UNSCOPED_INFO(describe(m));
    CHECK(a.total().traced() == 100000);
    CHECK(a.pass());
}

TEST_CASE("Hits on a shared edge or vertex are ties or edge hits, not disagreements", "[embree]") {
    // One quad split along its diagonal (0,0)-(1,1), and a fan of four triangles around (2,0.5).
    Scene s;
    s.materials.push_back(Material{});
    s.positions = {{0.f, 0.f, 0.f},  {1.f, 0.f, 0.f},  {1.f, 1.f, 0.f},
                   {0.f, 1.f, 0.f},  {2.f, 0.5f, 0.f}, {1.5f, 0.f, 0.f},
                   {2.5f, 0.f, 0.f}, {2.5f, 1.f, 0.f}, {1.5f, 1.f, 0.f}};
    s.triangles = {{0, 1, 2, 0}, {0, 2, 3, 0}, {4, 5, 6, 0},
                   {4, 6, 7, 0}, {4, 7, 8, 0}, {4, 8, 5, 0}};
    const Bvh bvh(s);
    const EmbreeScene embree(s);

    // Rays straight down onto the diagonal, onto the fan's center and its spokes, and from
    // oblique directions, so the shared edge is hit exactly and from both sides.
    std::vector<Ray> rays;
    for (int i = 1; i < 64; ++i) {  // interior points: the mesh's outer corners may miss
        const float f = float(i) / 64.f;
        for (const Vec3 d :
             {Vec3(0.f, 0.f, -1.f), Vec3(0.3f, -0.2f, -1.f), Vec3(-0.4f, 0.1f, -1.f)}) {
            rays.push_back({Vec3(f, f, 0.f) - d * 3.f, d});             // the diagonal
            rays.push_back({Vec3(2.f, 0.5f, 0.f) - d * (1.f + f), d});  // the fan's center
            rays.push_back({Vec3(2.f - 0.5f * f, 0.5f - 0.5f * f, 0.f) - d * 2.f, d});  // a spoke
        }
    }
    ClassCounts counts;
    std::vector<HitMismatch> examples;
    EmbreeCheckOptions options;
    options.threads = 1;
    const std::vector<Hit> hits =
        compare_rays(s, bvh, embree, rays, CheckRayKind::primary, options, counts, examples);
    CHECK(counts.traced() == rays.size());
    CHECK(counts.unexplained() == 0);
    CHECK(examples.empty());
    // sfx's watertight test lets none of them through.
    for (const Hit& h : hits) CHECK(h.valid());

    // Classification itself, with hits made up by hand.
    const Ray down{{0.5f, 0.5f, 3.f}, {0.f, 0.f, -1.f}};
    Hit on_edge_a;  // prim 0 at the diagonal: weight of p0 is 0.5, p1 0, p2 0.5
    on_edge_a.t = 3.f;
    on_edge_a.u = 0.f;
    on_edge_a.v = 0.5f;
    on_edge_a.prim = 0;
    Hit on_edge_b = on_edge_a;  // prim 1 at the same point
    on_edge_b.prim = 1;
    on_edge_b.u = 0.5f;
    on_edge_b.v = 0.f;
    CHECK(classify_hits(s, down, on_edge_a, on_edge_b) == HitClass::tie);
    Hit b_later = on_edge_b;
    b_later.t = 3.001f;
    CHECK(classify_hits(s, down, on_edge_a, b_later) == HitClass::edge);
    CHECK(classify_hits(s, down, on_edge_a, Hit{}) == HitClass::edge);
    // The same pair of primitives hit in their interiors at different t is a disagreement.
    Hit inner_a = on_edge_a, inner_b = b_later;
    inner_a.u = inner_a.v = 0.3f;
    inner_b.u = inner_b.v = 0.3f;
    CHECK(classify_hits(s, down, inner_a, inner_b) == HitClass::disagree);
    CHECK(classify_hits(s, down, inner_a, Hit{}) == HitClass::hit_miss);
    Hit inner_a_far = inner_a;
    inner_a_far.t = 3.01f;
    CHECK(classify_hits(s, down, inner_a, inner_a_far) == HitClass::same_prim_apart);
    Hit inner_a_ulps = inner_a;
    inner_a_ulps.t = std::nextafter(std::nextafter(inner_a.t, 4.f), 4.f);
    CHECK(classify_hits(s, down, inner_a, inner_a_ulps) == HitClass::agree);

    // Tolerances grow with 1/|cos| of the hit angle: u off by 3e-4 is rounding at cos = 0.001,
    // and a real difference at normal incidence.
    const Ray grazing{{-0.5f, 0.3f, 0.001f}, normalize(Vec3(1.f, 0.f, -0.001f))};
    Hit g = inner_a;
    g.t = 1.f;
    g.u = 0.2f;
    g.v = 0.3f;
    Hit g_off = g;
    g_off.u += 3e-4f;
    CHECK(classify_hits(s, grazing, g, g_off) == HitClass::agree);
    CHECK(classify_hits(s, down, g, g_off) == HitClass::same_prim_apart);

    // A hit at the origin (the origin lies on a surface) against a miss is an edge case; the
    // same hit well away from the origin is not.
    const Ray from_surface{{0.5f, 0.3f, 0.f}, {0.f, 0.f, 1.f}};
    Hit at_origin = g;
    at_origin.t = 1e-9f;
    CHECK(classify_hits(s, from_surface, at_origin, Hit{}) == HitClass::edge);
    at_origin.t = 0.5f;
    CHECK(classify_hits(s, from_surface, at_origin, Hit{}) == HitClass::hit_miss);
}

TEST_CASE("Sphere silhouettes are edge cases, sphere centers are not", "[embree]") {
    Scene s;
    s.materials.push_back(Material{});
    s.spheres.push_back({{0.f, 0.f, 0.f}, 1.f, 0});
    Hit hit;
    hit.t = 5.f;
    hit.prim = 0;
    const Ray tangent{{1.f, 0.f, -5.f}, {0.f, 0.f, 1.f}};
    CHECK(classify_hits(s, tangent, hit, Hit{}) == HitClass::edge);
    CHECK(classify_hits(s, tangent, Hit{}, hit) == HitClass::edge);
    const Ray central{{0.f, 0.f, -5.f}, {0.f, 0.f, 1.f}};
    hit.t = 4.f;
    CHECK(classify_hits(s, central, hit, Hit{}) == HitClass::hit_miss);
    // And Embree's sphere (RTC_GEOMETRY_TYPE_SPHERE_POINT) agrees with sfx's through the center.
    const Bvh bvh(s);
    const EmbreeScene embree(s);
    const Hit mine = bvh.intersect(central), theirs = embree.intersect(central);
    CHECK(classify_hits(s, central, mine, theirs) == HitClass::agree);
    CHECK(theirs.prim == 0);
    CHECK(theirs.t == Approx(4.f));
}

TEST_CASE("NaN, Inf and out-of-range rays are filtered and never reach Embree", "[embree]") {
    // Each of these rays, given to rtcIntersect1, aborts the process (Embree's ray.valid()
    // assertion), so reaching the end of this test is the proof that none got through.
    const Scene scene = make_room();
    const Bvh bvh(scene);
    const EmbreeScene embree(scene);
    const float nan = std::nanf(""), inf = INFINITY;
    const std::vector<Ray> bad = {
        {{nan, 0.f, 0.f}, {0.f, 0.f, -1.f}},        {{0.f, 0.f, 0.f}, {0.f, nan, -1.f}},
        {{inf, 0.f, 0.f}, {0.f, 0.f, -1.f}},        {{0.f, 0.f, 0.f}, {-inf, 0.f, -1.f}},
        {{0.f, 0.f, 0.f}, {0.f, 0.f, 0.f}},         {{0.f, 0.f, 0.f}, {0.f, 0.f, -1.f}, nan},
        {{0.f, 0.f, 0.f}, {0.f, 0.f, -1.f}, -1.f},  {{2e18f, 0.f, 0.f}, {0.f, 0.f, -1.f}},
        {{0.f, 0.f, -3e18f}, {0.f, 0.f, 1.f}},      {{0.f, 0.f, 0.f}, {1e30f, 0.f, -1.f}},
        {{0.f, 0.f, 0.f}, {0.f, 0.f, -1.f}, 1e30f},
    };
    std::vector<Ray> rays;
    for (const Ray& r : bad) {
        CHECK_FALSE(EmbreeScene::accepts(r));
        CHECK_FALSE(embree.intersect(r).valid());  // refused inside intersect too
        rays.push_back(r);
        rays.push_back({{0.f, 0.f, 0.f}, {0.1f, 0.2f, -1.f}});  // a good ray between bad ones
    }
    ClassCounts counts;
    std::vector<HitMismatch> examples;
    EmbreeCheckOptions options;
    options.threads = 2;
    const std::vector<Hit> hits =
        compare_rays(scene, bvh, embree, rays, CheckRayKind::primary, options, counts, examples);
    CHECK(counts.filtered == bad.size());
    CHECK(counts.traced() == bad.size());
    CHECK(counts.by_class[size_t(HitClass::agree)] == bad.size());
    for (size_t i = 0; i < rays.size(); i += 2) CHECK_FALSE(hits[i].valid());
    // Infinite t_max is Embree's own "unbounded" and is accepted.
    CHECK(EmbreeScene::accepts({{0.f, 0.f, 0.f}, {0.f, 0.f, -1.f}, INFINITY}));
}

TEST_CASE("A triangle moved in Embree's copy of the scene is detected", "[embree]") {
    const Scene scene = make_room();
    const Bvh bvh(scene);
    // The back wall (z = -1) is the room's first grid; move the first triangle of its cell
    // (2, 2), which the camera looks at, 5 cm toward the camera, with vertices of its own so
    // its neighbours stay put.
    const uint32_t moved = 2 * (2 * 6 + 2);
    EmbreeCheckOptions options = small_options(50000);
    options.embree_scene_edit = [&](Scene& s) {
        Triangle& t = s.triangles[moved];
        const Vec3 shift(0.f, 0.f, 0.05f);
        const uint32_t base = uint32_t(s.positions.size());
        s.positions.push_back(s.positions[t.v0] + shift);
        s.positions.push_back(s.positions[t.v1] + shift);
        s.positions.push_back(s.positions[t.v2] + shift);
        t.v0 = base;
        t.v1 = base + 1;
        t.v2 = base + 2;
    };
    REQUIRE(scene.positions[scene.triangles[moved].v0].z == -1.f);
    const EmbreeAgreement a = check_against_embree(scene, bvh, options);
    const ClassCounts total = a.total();
    INFO("same_prim_apart " << total.by_class[size_t(HitClass::same_prim_apart)] << " disagree "
                            << total.by_class[size_t(HitClass::disagree)]);
    CHECK(total.by_class[size_t(HitClass::same_prim_apart)] > 0);
    CHECK(total.unexplained() > 10);
    CHECK_FALSE(a.pass());
    REQUIRE_FALSE(a.examples.empty());
    CHECK(a.examples.size() <= options.max_examples);
    CHECK(!is_explained(a.examples.front().cls));
}
