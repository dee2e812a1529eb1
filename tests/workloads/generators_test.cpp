// Procedural generators: deterministic from their seed, and the shipped paper-class scenes hit
// the paper's Table 1 primitive counts (within 10 %) and light counts (exactly).

#include <catch2/catch.hpp>
#include <cmath>

#include "kernels/bvh.h"
#include "workloads/generators.h"
#include "workloads/ray_layout.h"
#include "workloads/scene_loader.h"

using namespace sfx;

namespace {

// Runs a generator with small parameters into a scene whose materials are all one grey,
// except that roles named like lights emit.
Scene generate(const std::string& name, uint64_t seed, const std::map<std::string, double>& overrides) {
    const GeneratorInfo* g = find_generator(name);
    REQUIRE(g != nullptr);
    Scene scene;
    GeneratorInput in;
    in.seed = seed;
    for (const GeneratorParam& p : g->params) in.params[p.name] = p.value;
    for (const auto& [k, v] : overrides) {
        REQUIRE(in.params.count(k) == 1);
        in.params[k] = v;
    }
    for (const std::string& role : g->material_roles) {
        Material m;
        m.name = role;
        if (role == "sky" || role == "lantern" || role == "panel" || role == "sanctuary") m.emission = Vec3(1.f);
        in.materials[role] = uint32_t(scene.materials.size());
        scene.materials.push_back(m);
    }
    SceneBuilder b(scene);
    g->build(in, b);
    scene.finalize(b.light_groups());
    return scene;
}

bool same_geometry(const Scene& a, const Scene& b) {
    if (a.positions.size() != b.positions.size() || a.triangles.size() != b.triangles.size() ||
        a.spheres.size() != b.spheres.size())
        return false;
    for (size_t i = 0; i < a.positions.size(); ++i)
        if (a.positions[i] != b.positions[i]) return false;
    for (size_t i = 0; i < a.triangles.size(); ++i)
        if (a.triangles[i].v0 != b.triangles[i].v0 || a.triangles[i].v1 != b.triangles[i].v1 ||
            a.triangles[i].v2 != b.triangles[i].v2 || a.triangles[i].material != b.triangles[i].material)
            return false;
    for (size_t i = 0; i < a.spheres.size(); ++i)
        if (a.spheres[i].center != b.spheres[i].center || a.spheres[i].radius != b.spheres[i].radius)
            return false;
    return true;
}

}  // namespace

TEST_CASE("generators are deterministic from their seed", "[workloads]") {
    const std::map<std::string, std::map<std::string, double>> small = {
        {"atrium", {{"column_rings", 4}, {"balusters_per_bay", 2}}},
        {"conference", {{"chair_detail", 6}, {"wall_chairs_per_side", 2}}},
        {"temple", {{"relief_density", 4}, {"column_rings", 8}, {"rubble_stones", 50}, {"statue_detail", 1}}},
    };
    for (const auto& [name, params] : small) {
        INFO(name);
        const Scene a = generate(name, 7, params);
        const Scene b = generate(name, 7, params);
        const Scene c = generate(name, 8, params);
        CHECK(a.primitive_count() > 0);
        CHECK(same_geometry(a, b));
        CHECK_FALSE(same_geometry(a, c));
        for (const Vec3& p : a.positions) REQUIRE(is_finite(p));
    }
}

TEST_CASE("generator registry lists parameters and material roles", "[workloads]") {
    REQUIRE(find_generator("temple") != nullptr);
    CHECK(find_generator("nonesuch") == nullptr);
    for (const GeneratorInfo& g : generators()) {
        CHECK_FALSE(g.material_roles.empty());
        for (const GeneratorParam& p : g.params) {
            INFO(g.name << "." << p.name);
            CHECK(p.min <= p.value);
            CHECK(p.value <= p.max);
        }
    }
}

TEST_CASE("shapes: box, grid, lathe and arch have the expected triangle counts", "[workloads]") {
    Scene s;
    s.materials.push_back(Material{});
    SceneBuilder b(s);
    shapes::box(b, Vec3(0.f), Vec3(1.f), 0);
    CHECK(s.triangles.size() == 12);
    shapes::grid(b, Vec3(0.f), Vec3(1.f, 0.f, 0.f), Vec3(0.f, 0.f, 1.f), 3, 5, 0);
    CHECK(s.triangles.size() == 12 + 30);
    shapes::lathe(b, Vec3(0.f), 2.f, 8, 4, 0, [](float, float) { return 1.f; });
    CHECK(s.triangles.size() == 12 + 30 + 64 + 16);
    const size_t before = s.triangles.size();
    shapes::arch(b, 1.f, 1.5f, 2.f, 0.5f, 8, 0, Transform{});
    CHECK(s.triangles.size() > before);
    for (uint32_t p = 0; p < s.primitive_count(); ++p) CHECK(s.primitive_area(p) > 0.f);
}

TEST_CASE("ray record: 96 bytes with every feature, fewer without", "[workloads]") {
    FeatureSet all;
    all.triangles = all.spheres = all.lambertian = all.dielectric = all.glossy = true;
    all.light_count = 2;
    CHECK(ray_record_bytes(all) == 96);
    FeatureSet lambert_tris;
    lambert_tris.triangles = lambert_tris.lambertian = true;
    CHECK(ray_record_bytes(lambert_tris) == 92);
    FeatureSet spheres;
    spheres.spheres = spheres.lambertian = true;
    CHECK(ray_record_bytes(spheres) == 84);
    uint32_t sum = 0;
    for (const RayField& f : ray_record_fields(all)) sum += f.bytes;
    CHECK(sum == 96);
}

TEST_CASE("every shipped scene loads", "[workloads]") {
    const std::vector<std::string> names = builtin_scene_names();
    for (const char* n : {"cornell", "furnace", "atrium", "conference"}) {
        INFO(n);
        CHECK(std::find(names.begin(), names.end(), n) != names.end());
        const Scene s = load_scene(n);
        CHECK(s.name == n);
        CHECK(s.primitive_count() > 0);
        CHECK(!s.lights.empty());
        CHECK(s.bounds().surface_area() > 0.f);
    }
    const Scene cornell = load_scene("cornell");
    CHECK(cornell.lights.size() == 1);
    CHECK(cornell.features().dielectric);
    CHECK(cornell.features().glossy);
    const Scene furnace = load_scene("furnace");
    CHECK(furnace.max_depth >= 64);
    CHECK(furnace.spheres.size() == 1);
}

TEST_CASE("atrium-ambient is atrium with a constant ambient term (the paper's rtrt, Sec. 4.2)",
          "[workloads]") {
    const Scene atrium = load_scene("atrium");
    const Scene rtrt = load_scene("atrium-ambient");
    CHECK(rtrt.name == "atrium-ambient");
    CHECK(rtrt.primitive_count() == atrium.primitive_count());
    CHECK(rtrt.lights.size() == atrium.lights.size());
    CHECK(rtrt.materials.size() == atrium.materials.size());
    CHECK(rtrt.max_depth == atrium.max_depth);
    CHECK(rtrt.camera.eye == atrium.camera.eye);
    CHECK(is_black(atrium.ambient));
    CHECK(!is_black(rtrt.ambient));
    CHECK(rtrt.features().ambient);
    CHECK(!atrium.features().ambient);
}

TEST_CASE("paper-class scenes match Table 1 (primitives within 10%, lights exactly)", "[workloads]") {
    struct Expect {
        const char* name;
        double primitives;
        size_t lights;
        bool spheres, dielectric, glossy;
    };
    // Gribble & Ramani 2008, Table 1: rtrt 83,845 / 2; conference 282,644 / 72; Kalabsha 2,124,001 / 2.
    for (const Expect& e : {Expect{"atrium", 83845, 2, true, true, true},
                            Expect{"conference", 282644, 72, false, false, true},
                            Expect{"temple", 2124001, 2, false, false, false}}) {
        INFO(e.name);
        const Scene s = load_scene(e.name);
        CHECK(std::fabs(double(s.primitive_count()) / e.primitives - 1.0) < 0.10);
        CHECK(s.lights.size() == e.lights);
        const FeatureSet f = s.features();
        CHECK(f.lambertian);
        CHECK(f.spheres == e.spheres);
        CHECK(f.dielectric == e.dielectric);
        CHECK(f.glossy == e.glossy);
        CHECK(s.max_depth == 3);
    }
}

TEST_CASE("generator parameters that together ask too much are refused up front", "[workloads]") {
    Scene scene;
    SceneBuilder b(scene);
    CHECK_THROWS_AS(b.expect(SceneBuilder::k_max_primitives + 1), TooManyPrimitives);
    CHECK_NOTHROW(b.expect(SceneBuilder::k_max_primitives));
    // The temple refuses before building anything: 10^6 stones of 81,920 triangles each.
    const GeneratorInfo* temple = find_generator("temple");
    REQUIRE(temple);
    GeneratorInput in;
    for (const GeneratorParam& p : temple->params) in.params[p.name] = p.value;
    for (const std::string& role : temple->material_roles) in.materials[role] = 0;
    in.params["rubble_stones"] = 1000000;
    in.params["rubble_detail"] = 6;
    Scene big;
    SceneBuilder bb(big);
    CHECK_THROWS_AS(temple->build(in, bb), TooManyPrimitives);
    CHECK(big.triangles.size() < 4000000);  // only the hall before the rubble was built
}
