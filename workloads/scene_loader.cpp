// Strict `*.scene.yaml` reader. Every key is checked: unknown or duplicate keys, wrong types,
// missing required keys and out-of-range values throw InputError(file, line, dotted key).
// The schema is documented in workloads/README.md.

#include "workloads/scene_loader.h"

#include <yaml-cpp/yaml.h>

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <iostream>
#include <map>
#include <set>

#include "workloads/generators.h"
#include "base/input_error.h"
#include "base/shipped_files.h"
#include "base/strict_number.h"
#include "base/strict_yaml.h"
#include "base/user_files.h"
#include "workloads/mesh_import.h"

#ifndef SFX_SCENE_DIR
#define SFX_SCENE_DIR "workloads/scenes"
#endif

namespace sfx {

namespace fs = std::filesystem;

namespace {

// Coordinates beyond this are refused: they overflow the ray math (and abort Embree).
constexpr double k_max_coordinate = 1e15;

class Reader {
public:
    explicit Reader(std::string file) : m_file(std::move(file)) {}

    [[noreturn]] void fail(const YAML::Node& at, const std::string& key, const std::string& what) const {
        throw InputError(m_file, at.IsDefined() ? at.Mark().line + 1 : 0, key, what);
    }

    // Checks that `node` is a map with only `allowed` keys (each once) and `required` present.
    void check_map(const YAML::Node& node, const std::string& path,
                   const std::set<std::string>& allowed, const std::set<std::string>& required) const {
        if (!node.IsMap()) fail(node, path, "expected a mapping");
        strict_yaml::check_keys(node, m_file, path,
                                std::vector<std::string>(allowed.begin(), allowed.end()));
        for (const std::string& r : required)
            if (!node[r]) fail(node, join(path, r), "missing required key");
    }

    // Numbers follow the rules of every YAML reader (base/strict_yaml.h): a quoted "1.5" is
    // text, refused rather than guessed at.
    double number(const YAML::Node& node, const std::string& key) const {
        if (!strict_yaml::is_plain_scalar(node)) fail(node, key, "expected a number");
        double v = 0;
        switch (strict_yaml::read_finite(node, v)) {
            case strict_yaml::NumberText::finite:
                return v;
            case strict_yaml::NumberText::not_finite:
                fail(node, key, "must be finite, got '" + node.Scalar() + "'");
            case strict_yaml::NumberText::not_a_number:
                fail(node, key, "expected a number, got '" + node.Scalar() + "'");
        }
        fail(node, key, "expected a number");
    }

    double number_in(const YAML::Node& node, const std::string& key, double lo, double hi,
                     bool lo_open = false) const {
        const double v = number(node, key);
        if (v < lo || v > hi || (lo_open && v == lo))
            fail(node, key, "must be in " + std::string(lo_open ? "(" : "[") + fmt(lo) + ", " +
                                fmt(hi) + "], got " + node.Scalar());
        return v;
    }

    int64_t integer(const YAML::Node& node, const std::string& key, int64_t lo, int64_t hi) const {
        if (!strict_yaml::is_plain_scalar(node)) fail(node, key, "expected an integer");
        int64_t v = 0;
        if (!parse_signed(node.Scalar(), v))
            fail(node, key, "expected an integer, got '" + node.Scalar() + "'");
        if (v < lo || v > hi)
            fail(node, key, "must be in [" + std::to_string(lo) + ", " + std::to_string(hi) +
                                "], got " + node.Scalar());
        return v;
    }

    uint64_t seed(const YAML::Node& node, const std::string& key) const {
        uint64_t v = 0;
        if (!strict_yaml::is_plain_scalar(node)) fail(node, key, "expected a non-negative integer");
        if (!parse_unsigned(node.Scalar(), v))
            fail(node, key, "expected a non-negative integer, got '" + node.Scalar() + "'");
        return v;
    }

    std::string string(const YAML::Node& node, const std::string& key) const {
        if (!node.IsScalar() || node.Scalar().empty()) fail(node, key, "expected a non-empty string");
        return node.Scalar();
    }

    Vec3 vec3(const YAML::Node& node, const std::string& key, double lo = -k_max_coordinate,
              double hi = k_max_coordinate) const {
        if (!node.IsSequence() || node.size() != 3) fail(node, key, "expected [x, y, z]");
        Vec3 v;
        for (int i = 0; i < 3; ++i)
            v[i] = float(number_in(node[i], key + "[" + std::to_string(i) + "]", lo, hi));
        return v;
    }

    const std::string& file() const { return m_file; }

    static std::string join(const std::string& path, const std::string& key) {
        return strict_yaml::join(path, key);
    }

private:
    static std::string fmt(double v) {
        char buf[32];
        std::snprintf(buf, sizeof buf, "%g", v);
        return buf;
    }
    std::string m_file;
};


Material parse_material(const Reader& r, const YAML::Node& node, const std::string& path) {
    r.check_map(node, path,
                {"name", "kind", "diffuse", "specular", "exponent", "ior", "transmission", "emission"},
                {"name", "kind"});
    Material m;
    m.name = r.string(node["name"], path + ".name");
    const std::string kind = r.string(node["kind"], path + ".kind");
    std::string names;
    bool known = false;
    for (MaterialKind k : k_material_kinds) {
        if (kind == to_string(k)) m.kind = k, known = true;
        names += (names.empty() ? "" : ", ") + std::string(to_string(k));
    }
    if (!known) r.fail(node["kind"], path + ".kind", "unknown kind '" + kind + "' (" + names + ")");
    // Keys that the kind does not use are errors: a typo'd kind must not silently drop them.
    auto only_for = [&](const char* key, bool ok, const char* kinds) {
        if (node[key] && !ok) r.fail(node[key], path + "." + key, std::string("applies to ") + kinds + " materials only");
    };
    const bool lam = m.kind == MaterialKind::lambertian, die = m.kind == MaterialKind::dielectric;
    const bool glo = m.kind == MaterialKind::glossy;
    only_for("diffuse", lam || glo, "lambertian and glossy");
    only_for("specular", glo, "glossy");
    only_for("exponent", glo, "glossy");
    only_for("ior", die, "dielectric");
    only_for("transmission", die, "dielectric");
    if (node["diffuse"]) m.diffuse = r.vec3(node["diffuse"], path + ".diffuse", 0.0, 1.0);
    if (node["specular"]) m.specular = r.vec3(node["specular"], path + ".specular", 0.0, 1.0);
    if (node["exponent"]) m.exponent = float(r.number_in(node["exponent"], path + ".exponent", 0.0, 1e6, true));
    if (node["ior"]) m.ior = float(r.number_in(node["ior"], path + ".ior", 0.0, 100.0, true));
    if (node["transmission"]) m.transmission = r.vec3(node["transmission"], path + ".transmission", 0.0, 1.0);
    if (node["emission"]) m.emission = r.vec3(node["emission"], path + ".emission", 0.0, 1e9);
    return m;
}

ThinLensCamera parse_camera(const Reader& r, const YAML::Node& node, const std::string& path) {
    r.check_map(node, path,
                {"eye", "look_at", "up", "vertical_fov_degrees", "aperture_radius", "focal_distance"},
                {"eye", "look_at"});
    ThinLensCamera c;
    c.eye = r.vec3(node["eye"], path + ".eye");
    c.look_at = r.vec3(node["look_at"], path + ".look_at");
    if (node["up"]) c.up = r.vec3(node["up"], path + ".up");
    if (node["vertical_fov_degrees"])
        c.vertical_fov_degrees = float(r.number_in(node["vertical_fov_degrees"],
                                                   path + ".vertical_fov_degrees", 0.0, 179.0, true));
    if (node["aperture_radius"])
        c.aperture_radius = float(r.number_in(node["aperture_radius"], path + ".aperture_radius", 0.0, 1e6));
    if (node["focal_distance"])
        c.focal_distance = float(r.number_in(node["focal_distance"], path + ".focal_distance", 0.0, 1e9, true));
    else if (c.aperture_radius > 0.f)
        r.fail(node, path + ".focal_distance", "required when aperture_radius > 0");
    const Vec3 view = c.look_at - c.eye;
    if (!(length(view) > 0.f)) r.fail(node["look_at"], path + ".look_at", "must differ from eye");
    if (!(length(cross(view, c.up)) > 1e-6f * length(view) * length(c.up)))
        r.fail(node["up"] ? node["up"] : node, path + ".up", "must not be zero or parallel to the view direction");
    return c;
}

Transform parse_transform(const Reader& r, const YAML::Node& node, const std::string& path) {
    r.check_map(node, path, {"scale", "rotate_degrees", "translate"}, {});
    Vec3 scale(1.f), rotate(0.f), translate(0.f);
    if (const YAML::Node s = node["scale"]) {
        if (s.IsScalar()) scale = Vec3(float(r.number(s, path + ".scale")));
        else scale = r.vec3(s, path + ".scale");
        for (int i = 0; i < 3; ++i)
            if (scale[i] == 0.f) r.fail(s, path + ".scale", "must be non-zero");
    }
    if (node["rotate_degrees"]) rotate = r.vec3(node["rotate_degrees"], path + ".rotate_degrees", -36000.0, 36000.0);
    if (node["translate"]) translate = r.vec3(node["translate"], path + ".translate");
    return Transform::make(scale, rotate, translate);
}

class SceneParser {
public:
    SceneParser(const std::string& file) : m_reader(file), m_dir(fs::path(file).parent_path()) {}

    Scene parse() {
        const Reader& r = m_reader;
        const YAML::Node loaded = parse_yaml_document(read_input_file(r.file(), "scene file"), r.file());
        const YAML::Node& root = loaded;  // const: lookups of missing keys must not insert them
        if (!root.IsMap()) throw InputError(r.file(), 1, "", "expected a mapping at the top level");
        r.check_map(root, "",
                    {"version", "name", "max_depth", "camera", "materials", "objects", "ambient", "environment"},
                    {"version", "camera", "materials", "objects"});
        if (r.integer(root["version"], "version", 0, 1000000) != 1)
            r.fail(root["version"], "version", "unsupported version (this sfx reads version 1)");
        Scene scene;
        std::string stem = fs::path(r.file()).filename().string();
        for (const char* suffix : {".scene.yaml", ".yaml", ".yml"})
            if (stem.size() > std::strlen(suffix) && stem.compare(stem.size() - std::strlen(suffix), std::string::npos, suffix) == 0) {
                stem.resize(stem.size() - std::strlen(suffix));
                break;
            }
        scene.name = root["name"] ? r.string(root["name"], "name") : stem;
        if (root["max_depth"]) scene.max_depth = uint32_t(r.integer(root["max_depth"], "max_depth", 0, 1000));
        scene.camera = parse_camera(r, root["camera"], "camera");
        if (root["ambient"]) scene.ambient = r.vec3(root["ambient"], "ambient", 0.0, 1e9);
        if (root["environment"]) scene.environment = r.vec3(root["environment"], "environment", 0.0, 1e9);

        const YAML::Node materials = root["materials"];
        if (!materials.IsSequence() || materials.size() == 0)
            r.fail(materials, "materials", "expected a non-empty list of materials");
        for (size_t i = 0; i < materials.size(); ++i) {
            const std::string path = "materials[" + std::to_string(i) + "]";
            Material m = parse_material(r, materials[i], path);
            if (!m_material_index.emplace(m.name, uint32_t(scene.materials.size())).second)
                r.fail(materials[i]["name"], path + ".name", "duplicate material name '" + m.name + "'");
            scene.materials.push_back(std::move(m));
        }

        const YAML::Node objects = root["objects"];
        if (!objects.IsSequence() || objects.size() == 0)
            r.fail(objects, "objects", "expected a non-empty list of objects");
        SceneBuilder builder(scene);
        for (size_t i = 0; i < objects.size(); ++i) {
            builder.begin_object();
            const size_t first_vertex = scene.positions.size();
            const std::string path = "objects[" + std::to_string(i) + "]";
            parse_object(objects[i], path, builder);
            for (size_t v = first_vertex; v < scene.positions.size(); ++v) {
                const Vec3& p = scene.positions[v];
                if (!is_finite(p) || std::fabs(p.x) > k_max_coordinate || std::fabs(p.y) > k_max_coordinate ||
                    std::fabs(p.z) > k_max_coordinate)
                    r.fail(objects[i], path, "produces a vertex that is not finite or beyond 1e15");
            }
        }
        scene.finalize(builder.light_groups());
        return scene;
    }

private:
    uint32_t material(const YAML::Node& node, const std::string& key) const {
        const std::string name = m_reader.string(node, key);
        auto it = m_material_index.find(name);
        if (it == m_material_index.end()) m_reader.fail(node, key, "unknown material '" + name + "'");
        return it->second;
    }

    void parse_object(const YAML::Node& node, const std::string& path, SceneBuilder& b) {
        const Reader& r = m_reader;
        if (!node.IsMap()) r.fail(node, path, "expected a mapping");
        if (!node["type"]) r.fail(node, path + ".type", "missing required key");
        const std::string type = r.string(node["type"], path + ".type");
        if (type == "quad") {
            r.check_map(node, path, {"type", "material", "origin", "edge_u", "edge_v"},
                        {"material", "origin", "edge_u", "edge_v"});
            const uint32_t m = material(node["material"], path + ".material");
            const Vec3 o = r.vec3(node["origin"], path + ".origin");
            const Vec3 u = r.vec3(node["edge_u"], path + ".edge_u");
            const Vec3 v = r.vec3(node["edge_v"], path + ".edge_v");
            if (!(length(cross(u, v)) > 0.f)) r.fail(node["edge_v"], path + ".edge_v", "edges must span a non-zero area");
            shapes::quad(b, o, u, v, m);
        } else if (type == "triangle") {
            r.check_map(node, path, {"type", "material", "vertices"}, {"material", "vertices"});
            const uint32_t m = material(node["material"], path + ".material");
            const YAML::Node vs = node["vertices"];
            if (!vs.IsSequence() || vs.size() != 3) r.fail(vs, path + ".vertices", "expected three [x, y, z] points");
            Vec3 p[3];
            for (int k = 0; k < 3; ++k) p[k] = r.vec3(vs[k], path + ".vertices[" + std::to_string(k) + "]");
            if (!(length(cross(p[1] - p[0], p[2] - p[0])) > 0.f))
                r.fail(vs, path + ".vertices", "the triangle has zero area");
            const uint32_t a = b.add_vertex(p[0]), c = b.add_vertex(p[1]), d = b.add_vertex(p[2]);
            b.add_triangle(a, c, d, m);
        } else if (type == "box") {
            r.check_map(node, path, {"type", "material", "min", "max", "transform"}, {"material", "min", "max"});
            const uint32_t m = material(node["material"], path + ".material");
            const Vec3 lo = r.vec3(node["min"], path + ".min");
            const Vec3 hi = r.vec3(node["max"], path + ".max");
            if (!(hi.x > lo.x && hi.y > lo.y && hi.z > lo.z))
                r.fail(node["max"], path + ".max", "must exceed min on every axis");
            if (node["transform"]) {
                const Transform xf = parse_transform(r, node["transform"], path + ".transform");
                shapes::box(b, lo, hi, m, &xf);
            } else {
                shapes::box(b, lo, hi, m);
            }
        } else if (type == "sphere") {
            r.check_map(node, path, {"type", "material", "center", "radius"}, {"material", "center", "radius"});
            const uint32_t m = material(node["material"], path + ".material");
            const Vec3 c = r.vec3(node["center"], path + ".center");
            const float radius = float(r.number_in(node["radius"], path + ".radius", 0.0, k_max_coordinate, true));
            b.add_sphere(c, radius, m);
        } else if (type == "mesh") {
            r.check_map(node, path, {"type", "material", "file", "transform"}, {"material", "file"});
            const uint32_t m = material(node["material"], path + ".material");
            const std::string file = r.string(node["file"], path + ".file");
            const fs::path full = fs::path(file).is_absolute() ? fs::path(file) : m_dir / file;
            Transform xf;
            if (node["transform"]) xf = parse_transform(r, node["transform"], path + ".transform");
            TriangleMesh mesh;
            try {
                mesh = import_mesh(full.string());
                b.expect(mesh.triangle_count());
                for (const std::string& w : mesh.warnings)
                    std::cerr << "sfx: warning: " << r.file() << ":" << strict_yaml::line_of(node["file"]) << ": " << path
                              << ".file: mesh '" << full.string() << "': " << w << "\n";
            } catch (const InputError& e) {
                r.fail(node["file"], path + ".file", "mesh '" + full.string() + "': " + e.message());
            } catch (const std::exception& e) {
                r.fail(node["file"], path + ".file", "mesh '" + full.string() + "': " + e.what());
            }
            const uint32_t base = uint32_t(b.scene().positions.size());
            for (size_t v = 0; v < mesh.positions.size(); ++v) {
                const Vec3 p = xf.apply(mesh.positions[v]);
                if (!std::isfinite(p.x) || !std::isfinite(p.y) || !std::isfinite(p.z))
                    r.fail(node["transform"], path + ".transform",
                           "moves vertex " + std::to_string(v) + " of '" + full.string() + "' out of float range");
                b.add_vertex(p);
            }
            for (size_t t = 0; t + 2 < mesh.indices.size(); t += 3)
                b.add_triangle(base + mesh.indices[t], base + mesh.indices[t + 1], base + mesh.indices[t + 2], m);
        } else if (type == "generator") {
            parse_generator(node, path, b);
        } else {
            r.fail(node["type"], path + ".type",
                   "unknown object type '" + type + "' (quad, triangle, box, sphere, mesh, generator)");
        }
    }

    void parse_generator(const YAML::Node& node, const std::string& path, SceneBuilder& b) {
        const Reader& r = m_reader;
        if (!node["generator"]) r.fail(node, path + ".generator", "missing required key");
        const std::string name = r.string(node["generator"], path + ".generator");
        const GeneratorInfo* g = find_generator(name);
        if (!g) {
            std::string list;
            for (const GeneratorInfo& gi : generators()) list += (list.empty() ? "" : ", ") + gi.name;
            r.fail(node["generator"], path + ".generator", "unknown generator '" + name + "' (" + list + ")");
        }
        std::set<std::string> allowed = {"type", "generator", "seed", "materials"};
        for (const GeneratorParam& p : g->params) allowed.insert(p.name);
        r.check_map(node, path, allowed, {"materials"});
        GeneratorInput in;
        if (node["seed"]) in.seed = r.seed(node["seed"], path + ".seed");
        for (const GeneratorParam& p : g->params) {
            const YAML::Node v = node[p.name];
            const std::string key = path + "." + p.name;
            if (!v) in.params[p.name] = p.value;
            else if (p.integer) in.params[p.name] = double(r.integer(v, key, int64_t(p.min), int64_t(p.max)));
            else in.params[p.name] = r.number_in(v, key, p.min, p.max);
        }
        const YAML::Node roles = node["materials"];
        const std::set<std::string> role_set(g->material_roles.begin(), g->material_roles.end());
        r.check_map(roles, path + ".materials", role_set, role_set);
        for (const std::string& role : g->material_roles)
            in.materials[role] = material(roles[role], path + ".materials." + role);
        try {
            g->build(in, b);
        } catch (const TooManyPrimitives& e) {
            std::string given;  // the parameters this file sets: together they ask too much
            for (const GeneratorParam& p : g->params)
                if (node[p.name]) given += (given.empty() ? "" : ", ") + p.name + ": " + node[p.name].Scalar();
            r.fail(node, path, "generator " + name + " would make " + e.what() +
                                   (given.empty() ? std::string() : " with " + given) + "; lower them");
        }
    }

    Reader m_reader;
    fs::path m_dir;
    std::map<std::string, uint32_t> m_material_index;
};

fs::path scene_dir() { return shipped_dir("SFX_SCENE_DIR", SFX_SCENE_DIR); }

const char* const k_shipped[] = {"cornell", "furnace", "atrium", "conference", "temple"};

}  // namespace

Scene load_scene(const std::string& name_or_path) {
    std::error_code ec;
    const bool plain_name = is_shipped_name(name_or_path);
    // Anything else that exists is read as a path (and refused there if it is not a regular
    // file); a directory that happens to share a built-in scene's name is not.
    const fs::file_status st = fs::status(name_or_path, ec);
    if (fs::exists(st) && !(plain_name && fs::is_directory(st))) return SceneParser(name_or_path).parse();
    if (plain_name) {
        const fs::path p = scene_dir() / (name_or_path + ".scene.yaml");
        if (fs::is_regular_file(p, ec)) return SceneParser(p.string()).parse();
    }
    std::string list;
    for (const std::string& n : builtin_scene_names()) list += (list.empty() ? "" : ", ") + n;
    throw InputError(name_or_path, 0, "",
                     "no such scene file, nor a built-in scene in " + scene_dir().string() +
                         " (built-in: " + list + ")");
}

std::vector<std::string> builtin_scene_names() {
    // The shipped scenes first in a fixed order, then any other scene files, sorted.
    std::vector<std::string> names;
    std::error_code ec;
    for (const char* n : k_shipped)
        if (fs::is_regular_file(scene_dir() / (std::string(n) + ".scene.yaml"), ec)) names.push_back(n);
    for (const std::string& n : shipped_names(scene_dir(), ".scene.yaml"))
        if (std::find(names.begin(), names.end(), n) == names.end()) names.push_back(n);
    return names;
}

}  // namespace sfx
