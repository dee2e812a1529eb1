// The strict scene loader: round trips of every object type, and every class of bad input
// reported with the right file, line and dotted key.

#include <catch2/catch.hpp>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <string>

#include "tests/temp_dir.h"
#include "base/input_error.h"
#include "workloads/scene_loader.h"

using namespace sfx;
namespace fs = std::filesystem;

namespace {

// A file in this process's own temporary directory (files of one test refer to each other by
// relative path); removed by the destructor.
struct TempFile {
    fs::path path;
    TempFile(const std::string& name, const std::string& text) {
        static const TempDir dir("sfx-scene-loader-test");
        path = dir.path / name;
        std::ofstream(path) << text;
    }
    ~TempFile() {
        std::error_code ec;
        fs::remove(path, ec);
    }
};

const char* const k_header =
    "version: 1\n"                                                            // 1
    "camera: {eye: [0, 0, 5], look_at: [0, 0, 0]}\n"                          // 2
    "materials:\n"                                                            // 3
    "  - {name: white, kind: lambertian, diffuse: [0.5, 0.5, 0.5]}\n"         // 4
    "  - {name: lamp, kind: lambertian, emission: [4, 4, 4]}\n"               // 5
    "objects:\n";                                                             // 6

// Loads `text` from a temp file and returns the InputError it must throw.
InputError load_error(const std::string& text) {
    TempFile f("bad.scene.yaml", text);
    try {
        load_scene(f.path.string());
    } catch (const InputError& e) {
        CHECK(e.file() == f.path.string());
        return e;
    }
    FAIL("no InputError for:\n" << text);
    return InputError("", 0, "", "");
}

void expect_error(const std::string& text, int line, const std::string& key,
                  const std::string& fragment = "") {
    const InputError e = load_error(text);
    INFO(e.what());
    CHECK(e.line() == line);
    CHECK(e.key() == key);
    if (!fragment.empty()) CHECK(std::string(e.what()).find(fragment) != std::string::npos);
}

}  // namespace

TEST_CASE("scene loader reads every object type", "[workloads]") {
    TempFile f("round.scene.yaml",
               std::string(k_header) +
                   "  - {type: quad, material: lamp, origin: [0, 2, 0], edge_u: [1, 0, 0], edge_v: [0, 0, 1]}\n"
                   "  - {type: sphere, material: white, center: [1, 2, 3], radius: 0.5}\n"
                   "  - {type: box, material: white, min: [0, 0, 0], max: [1, 1, 1],\n"
                   "     transform: {scale: 2, translate: [10, 0, 0]}}\n"
                   "  - {type: triangle, material: white, vertices: [[0, 0, 0], [1, 0, 0], [0, 1, 0]]}\n"
                   "max_depth: 7\n"
                   "ambient: [0.1, 0.2, 0.3]\n"
                   "name: round\n");
    const Scene s = load_scene(f.path.string());
    CHECK(s.name == "round");
    CHECK(s.max_depth == 7);
    CHECK(s.ambient == Vec3(0.1f, 0.2f, 0.3f));
    CHECK(s.camera.eye == Vec3(0.f, 0.f, 5.f));
    CHECK(s.camera.up == Vec3(0.f, 1.f, 0.f));
    REQUIRE(s.materials.size() == 2);
    CHECK(s.materials[0].diffuse == Vec3(0.5f));
    CHECK(s.materials[1].emission == Vec3(4.f));
    CHECK(s.triangles.size() == 2 + 12 + 1);
    REQUIRE(s.spheres.size() == 1);
    CHECK(s.spheres[0].center == Vec3(1.f, 2.f, 3.f));
    CHECK(s.spheres[0].radius == 0.5f);
    // Box corners scaled by 2 then moved by 10 in x.
    const Bounds3 box = [&] {
        Bounds3 b;
        for (uint32_t p = 2; p < 14; ++p) b.extend(s.primitive_bounds(p));
        return b;
    }();
    CHECK(box.lo == Vec3(10.f, 0.f, 0.f));
    CHECK(box.hi == Vec3(12.f, 2.f, 2.f));
    // The quad is one light of two triangles.
    REQUIRE(s.lights.size() == 1);
    CHECK(s.lights[0].primitives.size() == 2);
    CHECK(s.lights[0].area == Approx(1.f));
    const FeatureSet fs = s.features();
    CHECK(fs.triangles);
    CHECK(fs.spheres);
    CHECK(fs.ambient);
    CHECK(!fs.dielectric);
}

TEST_CASE("scene loader: a scene's name defaults to its file stem", "[workloads]") {
    TempFile f("stemmed.scene.yaml",
               std::string(k_header) + "  - {type: sphere, material: white, center: [0, 0, 0], radius: 1}\n");
    CHECK(load_scene(f.path.string()).name == "stemmed");
}

TEST_CASE("scene loader: unknown, duplicate and missing keys", "[workloads]") {
    const std::string sphere = "  - {type: sphere, material: white, center: [0, 0, 0], radius: 1}\n";
    expect_error(std::string(k_header) + sphere + "colour: red\n", 8, "colour", "unknown key");
    expect_error(std::string(k_header) + "  - {type: sphere, material: white, center: [0, 0, 0],\n"
                                         "     radius: 1, radius: 2}\n",
                 8, "objects[0].radius", "duplicate");
    expect_error(std::string(k_header) + "  - {type: sphere, material: white, center: [0, 0, 0]}\n",
                 7, "objects[0].radius", "missing");
    expect_error(std::string(k_header) + sphere + sphere + "  - {type: sphere, material: white,\n"
                                                           "     centre: [0, 0, 0], radius: 1}\n",
                 10, "objects[2].centre", "unknown key");
    expect_error("version: 1\nmaterials: [{name: a, kind: lambertian}]\nobjects: []\n", 1, "camera",
                 "missing");
    expect_error("camera: {eye: [0, 0, 5], look_at: [0, 0, 0]}\nmaterials: []\nobjects: []\n", 1,
                 "version", "missing");
    expect_error(std::string(k_header) + "  - {material: white, center: [0, 0, 0], radius: 1}\n", 7,
                 "objects[0].type", "missing");
    expect_error(std::string("version: 1\n"
                             "camera: {eye: [0, 0, 5], look_at: [0, 0, 0], fov: 40}\n"
                             "materials: [{name: a, kind: lambertian}]\n"
                             "objects: [{type: sphere, material: a, center: [0, 0, 0], radius: 1}]\n"),
                 2, "camera.fov", "unknown key");
}

TEST_CASE("scene loader: wrong types and bad values", "[workloads]") {
    const std::string h = k_header;
    expect_error(h + "  - {type: sphere, material: white, center: [0, 0, 0], radius: abc}\n", 7,
                 "objects[0].radius", "expected a number");
    expect_error(h + "  - {type: sphere, material: white, center: [0, 0, 0], radius: -1}\n", 7,
                 "objects[0].radius", "must be in");
    expect_error(h + "  - {type: sphere, material: white, center: [0, 0, 0], radius: '1'}\n", 7,
                 "objects[0].radius", "expected a number");
    expect_error(h + "  - {type: sphere, material: white, center: [0, 0, 0], radius: true}\n", 7,
                 "objects[0].radius", "expected a number");
    expect_error(h + "  - {type: sphere, material: white, center: [0, 0, 0], radius: [1]}\n", 7,
                 "objects[0].radius", "expected a number");
    expect_error(h + "  - {type: sphere, material: white, center: [0, 0], radius: 1}\n", 7,
                 "objects[0].center", "expected [x, y, z]");
    expect_error(h + "  - {type: sphere, material: white,\n     center: [0, .nan, 0], radius: 1}\n", 8,
                 "objects[0].center[1]", "finite");
    expect_error(h + "  - {type: sphere, material: white, center: [0, 0, .inf], radius: 1}\n", 7,
                 "objects[0].center[2]", "finite");
    expect_error(h + "  - {type: sphere, material: white, center: [0, 0, 1e999], radius: 1}\n", 7,
                 "objects[0].center[2]", "finite");
    // The number rules every YAML reader shares (base/strict_yaml.h): decimal only, one spelling.
    expect_error(h + "  - {type: sphere, material: white, center: [0, 0, 0], radius: 0x1}\n", 7,
                 "objects[0].radius", "expected a number, got '0x1'");
    expect_error(h + "  - {type: sphere, material: white, center: [0, 0, 0], radius: inf}\n", 7,
                 "objects[0].radius", "expected a number, got 'inf'");
    expect_error(h + "  - {type: sphere, material: white, center: [0, 0, 0], radius: +1}\n", 7,
                 "objects[0].radius", "expected a number, got '+1'");
    expect_error(h + "  - {type: sphere, material: chalk, center: [0, 0, 0], radius: 1}\n", 7,
                 "objects[0].material", "unknown material 'chalk'");
    expect_error(h + "  - {type: cone, material: white}\n", 7, "objects[0].type", "unknown object type");
    expect_error(h + "  - {type: quad, material: white, origin: [0, 0, 0], edge_u: [1, 0, 0],\n"
                     "     edge_v: [2, 0, 0]}\n",
                 8, "objects[0].edge_v", "non-zero area");
    expect_error(h + "  - {type: box, material: white, min: [0, 0, 0], max: [1, 0, 1]}\n", 7,
                 "objects[0].max", "exceed min");
    const std::string tail = "objects: [{type: sphere, material: g, center: [0, 0, 0], radius: 1}]\n";
    const std::string cam = "version: 1\ncamera: {eye: [0, 0, 5], look_at: [0, 0, 0]}\nmaterials:\n";
    expect_error(cam + "  - {name: g, kind: dielectric, ior: 0}\n" + tail, 4, "materials[0].ior",
                 "must be in");
    expect_error(cam + "  - {name: g, kind: dielectric, ior: -1.5}\n" + tail, 4, "materials[0].ior");
    expect_error(cam + "  - {name: g, kind: lambertian, ior: 1.5}\n" + tail, 4, "materials[0].ior",
                 "dielectric");
    expect_error(cam + "  - {name: g, kind: metal}\n" + tail, 4, "materials[0].kind", "unknown kind");
    expect_error(cam + "  - {name: g, kind: lambertian, diffuse: [1.5, 0, 0]}\n" + tail, 4,
                 "materials[0].diffuse[0]", "must be in");
    expect_error(cam + "  - {name: g, kind: lambertian, emission: [-1, 0, 0]}\n" + tail, 4,
                 "materials[0].emission[0]");
    expect_error(cam + "  - {name: g, kind: glossy, exponent: 0}\n" + tail, 4, "materials[0].exponent");
    expect_error(cam + "  - {name: g, kind: lambertian}\n  - {name: g, kind: glossy}\n" + tail, 5,
                 "materials[1].name", "duplicate material");
    expect_error("version: 2\ncamera: {eye: [0, 0, 5], look_at: [0, 0, 0]}\nmaterials: []\nobjects: []\n",
                 1, "version", "unsupported");
    expect_error("version: 1\ncamera: {eye: [0, 0, 5], look_at: [0, 0, 5]}\n"
                 "materials: [{name: g, kind: lambertian}]\n" + tail,
                 2, "camera.look_at", "differ");
    expect_error("version: 1\ncamera: {eye: [0, 0, 5], look_at: [0, 0, 0], aperture_radius: 0.1}\n"
                 "materials: [{name: g, kind: lambertian}]\n" + tail,
                 2, "camera.focal_distance", "required");
    expect_error(h + "  - {type: sphere, material: white, center: [0, 0, 0], radius: 1}\nmax_depth: 2.5\n",
                 8, "max_depth", "integer");
    expect_error(h + "  - {type: sphere, material: white, center: [0, 0, 0], radius: 1e300}\n", 7,
                 "objects[0].radius");
}

TEST_CASE("scene loader: YAML syntax errors and missing files", "[workloads]") {
    const InputError syntax = load_error(std::string(k_header) + "  - {type: sphere, radius: [1, 2\n");
    CHECK(syntax.line() >= 7);
    CHECK(std::string(syntax.what()).find("syntax") != std::string::npos);
    try {
        load_scene("/nonexistent/dir/none.scene.yaml");
        FAIL("no error");
    } catch (const InputError& e) {
        CHECK(e.file() == "/nonexistent/dir/none.scene.yaml");
    }
    CHECK_THROWS_AS(load_scene("no_such_builtin_scene"), InputError);
}

TEST_CASE("scene loader: generator objects are checked", "[workloads]") {
    const std::string cam = "version: 1\ncamera: {eye: [0, 0, 5], look_at: [0, 0, 0]}\n"
                            "materials: [{name: a, kind: lambertian}, {name: e, kind: lambertian, "
                            "emission: [1, 1, 1]}]\n"
                            "objects:\n";
    const std::string roles = "materials: {stone: a, relief: a, floor: a, sky: e, sanctuary: e}";
    expect_error(cam + "  - {type: generator, generator: pyramid, " + roles + "}\n", 5,
                 "objects[0].generator", "unknown generator");
    expect_error(cam + "  - {type: generator, generator: temple, towers: 3, " + roles + "}\n", 5,
                 "objects[0].towers", "unknown key");
    expect_error(cam + "  - {type: generator, generator: temple, column_rings: 0, " + roles + "}\n", 5,
                 "objects[0].column_rings", "must be in");
    expect_error(cam + "  - {type: generator, generator: temple, column_rings: 2.5, " + roles + "}\n", 5,
                 "objects[0].column_rings", "integer");
    expect_error(cam + "  - {type: generator, generator: temple, seed: -1, " + roles + "}\n", 5,
                 "objects[0].seed");
    expect_error(cam + "  - {type: generator, generator: temple,\n"
                       "     materials: {stone: a, relief: a, floor: a, sky: e}}\n",
                 6, "objects[0].materials.sanctuary", "missing");
    expect_error(cam + "  - {type: generator, generator: temple,\n"
                       "     materials: {stone: a, relief: a, floor: a, sky: e, sanctuary: nope}}\n",
                 6, "objects[0].materials.sanctuary", "unknown material");
}

TEST_CASE("scene loader: a bad mesh names the scene file, line, key and mesh path", "[workloads]") {
    const InputError e = load_error(std::string(k_header) +
                                    "  - {type: sphere, material: white, center: [0, 0, 0], radius: 1}\n"
                                    "  - {type: mesh, material: white, file: meshes/missing.obj}\n");
    CHECK(e.line() == 8);
    CHECK(e.key() == "objects[1].file");
    CHECK(std::string(e.what()).find("meshes/missing.obj") != std::string::npos);
    TempFile junk("junk.obj", "this is not\x01\x02 a mesh {{{\n");
    const InputError j = load_error(std::string(k_header) +
                                    "  - {type: mesh, material: white, file: junk.obj}\n");
    CHECK(j.key() == "objects[0].file");
    CHECK(j.line() == 7);
}

TEST_CASE("scene loader: SFX_SCENE_DIR overrides where named scenes are found", "[workloads]") {
    const TempDir temp("sfx-scene-dir-test");
    const fs::path& dir = temp.path;
    std::ofstream(dir / "tiny.scene.yaml")
        << "version: 1\ncamera: {eye: [0, 0, 5], look_at: [0, 0, 0]}\n"
           "materials: [{name: a, kind: lambertian}]\n"
           "objects: [{type: sphere, material: a, center: [0, 0, 0], radius: 2}]\n";
    const char* old = std::getenv("SFX_SCENE_DIR");
    const std::string saved = old ? old : "";
    setenv("SFX_SCENE_DIR", dir.string().c_str(), 1);
    const Scene s = load_scene("tiny");
    const std::vector<std::string> names = builtin_scene_names();
    if (old) setenv("SFX_SCENE_DIR", saved.c_str(), 1);
    else unsetenv("SFX_SCENE_DIR");
    CHECK(s.name == "tiny");
    CHECK(s.spheres.at(0).radius == 2.f);
    CHECK(names == std::vector<std::string>{"tiny"});
    CHECK(load_scene("cornell").name == "cornell");  // back to the shipped scenes
}

TEST_CASE("material kinds: the list names every kind once, in enum order", "[workloads]") {
    // A kind added to the enum (and so, by -Werror=switch, to to_string) but not to
    // k_material_kinds would be missed by every loop over kinds: names, counts, feature flags.
    for (uint32_t i = 0; i < k_material_kind_count; ++i) {
        CHECK(k_material_kinds[i] == MaterialKind(i));
        CHECK(std::string(to_string(MaterialKind(i))) != "?");
        FeatureSet f;
        f.*FeatureSet::material_flag(MaterialKind(i)) = true;
        CHECK(f.uses(MaterialKind(i)));
        CHECK(f.material_kinds() == 1);
    }
    CHECK(std::string(to_string(MaterialKind(k_material_kind_count))) == "?");
}
