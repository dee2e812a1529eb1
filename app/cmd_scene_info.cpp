// sfx scene-info SCENE: what a scene is made of and what it asks of a tracer and of hardware:
// primitive, light and material counts, the feature set, bytes per ray, BVH statistics, memory.

#include <cstdio>
#include <iostream>
#include <nlohmann/json.hpp>

#include "app/commands.h"
#include "kernels/bvh.h"
#include "base/host_clock.h"
#include "workloads/ray_layout.h"
#include "workloads/scene_loader.h"

namespace sfx {

void add_scene_info_command(CLI::App& app) {
    struct Options {
        std::string scene;
        bool json = false;
        bool layout = false;
    };
    auto options = std::make_shared<Options>();
    CLI::App* c = app.add_subcommand("scene-info", "primitives, lights, materials, features, BVH");
    c->add_option("scene", options->scene, "scene file or built-in scene name")->required();
    c->add_flag("--json", options->json, "print one JSON document");
    c->add_flag("--ray-layout", options->layout, "also list the ray record's fields");
    c->callback([options] {
        const auto load_start = HostClock::now();
        const Scene scene = load_scene(options->scene);
        const double load_seconds = seconds_since(load_start);
        const auto build_start = HostClock::now();
        const Bvh bvh(scene);
        const double build_seconds = seconds_since(build_start);
        const BvhStats st = bvh.stats();
        const FeatureSet features = scene.features();
        const auto fields = ray_record_fields(features);
        const uint32_t ray_bytes = ray_record_bytes(features);
        uint32_t kinds[k_material_kind_count] = {};
        for (const Material& m : scene.materials) ++kinds[int(m.kind)];
        uint32_t emissive = 0;
        for (const Material& m : scene.materials) emissive += m.emissive();
        uint64_t light_primitives = 0;
        for (const AreaLight& l : scene.lights) light_primitives += l.primitives.size();
        const Bounds3 bounds = scene.bounds();
        const uint64_t geometry = scene.geometry_bytes();
        if (options->json) {
            nlohmann::json j;
            j["scene"] = scene.name;
            j["primitives"] = scene.primitive_count();
            j["triangles"] = scene.triangles.size();
            j["spheres"] = scene.spheres.size();
            j["vertices"] = scene.positions.size();
            j["lights"] = scene.lights.size();
            j["light_primitives"] = light_primitives;
            j["materials"] = scene.materials.size();
            for (MaterialKind k : k_material_kinds)
                j[std::string("materials.") + to_string(k)] = kinds[int(k)];
            j["materials.emissive"] = emissive;
            j["features"] = features.describe();
            j["features.triangles"] = features.triangles;
            j["features.spheres"] = features.spheres;
            for (MaterialKind k : k_material_kinds)
                j[std::string("features.") + to_string(k)] = features.uses(k);
            j["features.thin_lens"] = features.thin_lens;
            j["features.ambient"] = features.ambient;
            j["features.environment"] = features.environment;
            j["features.light_count"] = features.light_count;
            j["features.sphere_light_share"] = features.sphere_light_share;
            j["features.max_depth"] = features.max_depth;
            j["ray_record_bytes"] = ray_bytes;
            for (const RayField& f : fields) j["ray_record." + f.name + "_bytes"] = f.bytes;
            j["bounds.lo"] = {bounds.lo.x, bounds.lo.y, bounds.lo.z};
            j["bounds.hi"] = {bounds.hi.x, bounds.hi.y, bounds.hi.z};
            j["bvh.nodes"] = st.nodes;
            j["bvh.leaves"] = st.leaves;
            j["bvh.max_depth"] = st.max_depth;
            j["bvh.average_leaf_depth"] = st.average_leaf_depth;
            j["bvh.average_leaf_size"] = st.average_leaf_size;
            j["bvh.max_leaf_size"] = st.max_leaf_size;
            j["bvh.sah_cost"] = st.sah_cost;
            j["bvh.bytes"] = st.bytes;
            j["bvh.build_seconds"] = build_seconds;
            j["load_seconds"] = load_seconds;
            j["isa"] = isa_name(best_isa());
            j["isas"] = nlohmann::json::array();  // every back end this CPU runs
            for (const Isa i : supported_isas()) j["isas"].push_back(isa_name(i));
            j["memory.geometry_bytes"] = geometry;
            j["memory.bvh_bytes"] = st.bytes;
            j["memory.total_bytes"] = geometry + st.bytes;
            std::cout << j.dump(2) << "\n";
            return;
        }
        auto mib = [](uint64_t bytes) {
            char buf[32];
            if (bytes < 1024 * 1024)
                std::snprintf(buf, sizeof buf, "%.1f KiB", double(bytes) / 1024.0);
            else
                std::snprintf(buf, sizeof buf, "%.2f MiB", double(bytes) / (1024.0 * 1024.0));
            return std::string(buf);
        };
        std::printf("scene              %s\n", scene.name.c_str());
        std::printf("primitives         %u (triangles %zu, spheres %zu), vertices %zu\n",
                    scene.primitive_count(), scene.triangles.size(), scene.spheres.size(),
                    scene.positions.size());
        std::printf("lights             %zu (%llu emissive primitives)\n", scene.lights.size(),
                    (unsigned long long)light_primitives);
        std::string per_kind;
        for (MaterialKind k : k_material_kinds)
            per_kind += (per_kind.empty() ? "" : ", ") + std::string(to_string(k)) + " " +
                        std::to_string(kinds[int(k)]);
        std::printf("materials          %zu (%s; emissive %u)\n", scene.materials.size(),
                    per_kind.c_str(), emissive);
        std::printf("features           %s\n", features.describe().c_str());
        std::printf("ray record         %u bytes (%u KiB for 64x64 rays)\n", ray_bytes,
                    ray_bytes * 4096 / 1024);
        if (options->layout)
            for (const RayField& f : fields)
                std::printf("  %-18s %2u  %s\n", f.name.c_str(), f.bytes, f.why.c_str());
        std::printf("bounds             [%g %g %g] .. [%g %g %g]\n", bounds.lo.x, bounds.lo.y,
                    bounds.lo.z, bounds.hi.x, bounds.hi.y, bounds.hi.z);
        std::printf("bvh                %llu nodes, %llu leaves, depth %u, built in %.3f s\n",
                    (unsigned long long)st.nodes, (unsigned long long)st.leaves, st.max_depth,
                    build_seconds);
        std::printf("bvh leaves         average depth %.2f, average size %.2f, max size %u\n",
                    st.average_leaf_depth, st.average_leaf_size, st.max_leaf_size);
        std::printf("bvh sah cost       %.3f\n", st.sah_cost);
        std::printf("memory             geometry %s, bvh %s, total %s\n", mib(geometry).c_str(),
                    mib(st.bytes).c_str(), mib(geometry + st.bytes).c_str());
        std::printf("load seconds       %.3f\n", load_seconds);
        std::printf(
            "stream back end    %s (widest this CPU runs; --isa on the rendering "
            "commands)\n",
            describe_isa(Isa::automatic).c_str());
    });
}

}  // namespace sfx
