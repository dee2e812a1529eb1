// sfx validate SCENE --against embree: checks sfx's BVH hits against Embree 3 on primary and
// diffuse-bounce rays. Exit 0 on pass, 1 on fail, 2 on bad input.
//
// Each --against target is one function below taking the loaded scene and the parsed flags;
// a new target (the stream tracer against the reference tracer) is one more function and one
// more name in k_targets.

#include <chrono>
#include <cstdio>
#include <iostream>
#include <nlohmann/json.hpp>
#include <stdexcept>

#include "app/commands.h"
#include "kernels/bvh.h"
#include "kernels/embree/embree_check.h"
#include "workloads/input_error.h"
#include "workloads/scene_loader.h"

namespace sfx {

namespace {

struct ValidateOptions {
    std::string scene;
    std::string against;
    uint64_t rays = 1000000;
    bool json = false;
    WorkloadFlags workload;
};

const std::vector<std::string> k_targets = {"embree"};

using Clock = std::chrono::steady_clock;
double seconds_since(Clock::time_point t) {
    return std::chrono::duration<double>(Clock::now() - t).count();
}

std::string format_rate(double r) {
    char buf[32];
    std::snprintf(buf, sizeof buf, "%.2e", r);
    return buf;
}

// Returns true on pass.
bool validate_against_embree(const ValidateOptions& o, const Scene& scene,
                             const RenderSettings& settings, Clock::time_point start,
                             double load_seconds) {
    if (o.rays == 0 || o.rays > 100000000)
        throw InputError("command line", 0, "--rays",
                         "expected 1..100000000, got " + std::to_string(o.rays));
    const auto bvh_start = Clock::now();
    const Bvh bvh(scene);
    const double bvh_seconds = seconds_since(bvh_start);

    EmbreeCheckOptions options;
    options.rays = o.rays;
    options.width = settings.width;
    options.height = settings.height;
    options.seed = settings.seed;
    options.threads = settings.threads;
    const EmbreeAgreement a = check_against_embree(scene, bvh, options);
    const double total_seconds = seconds_since(start);

    const ClassCounts& primary = a.by_kind[size_t(CheckRayKind::primary)];
    const ClassCounts& diffuse = a.by_kind[size_t(CheckRayKind::diffuse)];
    const ClassCounts total = a.total();
    if (o.json) {
        nlohmann::json j;
        j["scene"] = scene.name;
        j["against"] = o.against;
        j["primitives"] = scene.primitive_count();
        j["excluded_primitives"] = a.excluded_primitives;
        j["width"] = settings.width;
        j["height"] = settings.height;
        j["seed"] = settings.seed;
        j["rays"] = o.rays;
        j["diffuse_sources"] = a.diffuse_sources;
        for (const auto& [name, c] : {std::pair<std::string, const ClassCounts*>{"primary", &primary},
                                      {"diffuse", &diffuse},
                                      {"total", &total}}) {
            for (size_t k = 0; k < k_hit_class_count; ++k)
                j[name + "." + to_string(HitClass(k))] = c->by_class[k];
            j[name + ".filtered"] = c->filtered;
            j[name + ".traced"] = c->traced();
            j[name + ".explained"] = c->explained();
            j[name + ".unexplained"] = c->unexplained();
            j[name + ".unexplained_rate"] =
                c->traced() ? double(c->unexplained()) / double(c->traced()) : 0.0;
        }
        j["unexplained_rate"] = a.unexplained_rate();
        j["max_unexplained_rate"] = a.max_unexplained_rate;
        j["pass"] = a.pass();
        nlohmann::json examples = nlohmann::json::array();
        for (const HitMismatch& m : a.examples) examples.push_back(describe(m));
        j["examples"] = examples;
        j["host_seconds"] = total_seconds;
        j["host_seconds.load"] = load_seconds;
        j["host_seconds.bvh_build"] = bvh_seconds;
        j["host_seconds.embree_build"] = a.embree_build_seconds;
        j["host_seconds.trace"] = a.trace_seconds;
        std::cout << j.dump(2) << "\n";
        return a.pass();
    }

    std::printf("scene            %s (%u triangles, %zu spheres; %u left out of Embree)\n",
                scene.name.c_str(), scene.triangle_count(), scene.spheres.size(),
                a.excluded_primitives);
    std::printf("rays             %llu: primary at %ux%u, diffuse from %llu primary hits, seed %llu\n",
                (unsigned long long)o.rays, settings.width, settings.height,
                (unsigned long long)a.diffuse_sources, (unsigned long long)settings.seed);
    std::printf("\n%-18s %12s %12s %12s %10s\n", "class", "primary", "diffuse", "total", "rate");
    auto row = [&](const char* name, uint64_t p, uint64_t d, uint64_t t) {
        const double rate = total.traced() ? double(t) / double(total.traced()) : 0.0;
        std::printf("%-18s %12llu %12llu %12llu %10s\n", name, (unsigned long long)p,
                    (unsigned long long)d, (unsigned long long)t, format_rate(rate).c_str());
    };
    for (size_t k = 0; k < k_hit_class_count; ++k) {
        const std::string name = std::string(to_string(HitClass(k))) +
                                 (is_explained(HitClass(k)) ? "" : " *");
        row(name.c_str(), primary.by_class[k], diffuse.by_class[k], total.by_class[k]);
    }
    row("traced", primary.traced(), diffuse.traced(), total.traced());
    row("explained", primary.explained(), diffuse.explained(), total.explained());
    row("unexplained *", primary.unexplained(), diffuse.unexplained(), total.unexplained());
    std::printf("%-18s %12llu %12llu %12llu %10s\n", "filtered (not traced)",
                (unsigned long long)primary.filtered, (unsigned long long)diffuse.filtered,
                (unsigned long long)total.filtered, "");
    std::printf("\nunexplained rate %s (limit %s): %s\n", format_rate(a.unexplained_rate()).c_str(),
                format_rate(a.max_unexplained_rate).c_str(), a.pass() ? "PASS" : "FAIL");
    std::printf("host seconds     %.2f (load %.2f, sfx bvh %.2f, embree build %.2f, trace %.2f)\n",
                total_seconds, load_seconds, bvh_seconds, a.embree_build_seconds, a.trace_seconds);
    if (!a.examples.empty()) {
        std::printf("first unexplained rays:\n");
        for (const HitMismatch& m : a.examples) std::printf("  %s\n", describe(m).c_str());
    }
    return a.pass();
}

}  // namespace

void add_validate_command(CLI::App& app) {
    auto options = std::make_shared<ValidateOptions>();
    CLI::App* c = app.add_subcommand(
        "validate",
        "check sfx's hits against another tracer (embree: Embree 3 on primary and diffuse rays; "
        "classes marked * are unexplained; exit 1 if they exceed the limit)");
    c->add_option("scene", options->scene, "scene file or built-in scene name")->required();
    c->add_option("--against", options->against, "what to check against")
        ->required()
        ->check(CLI::IsMember(k_targets));
    c->add_option("--rays", options->rays, "rays in total, half primary and half diffuse")
        ->capture_default_str();
    c->add_flag("--json", options->json, "print one JSON document");
    // --res, --seed and --threads apply; --spp, --depth and --tile are accepted for uniformity
    // with the other commands but do not change the embree check.
    options->workload.add_to(c);
    c->callback([options] {
        const auto start = Clock::now();
        const Scene scene = load_scene(options->scene);
        const double load_seconds = seconds_since(start);
        const RenderSettings settings = options->workload.resolve(scene);
        bool pass = false;
        if (options->against == "embree")
            pass = validate_against_embree(*options, scene, settings, start, load_seconds);
        if (!pass) throw std::runtime_error("validate: " + options->against + " check failed");
    });
}

}  // namespace sfx
