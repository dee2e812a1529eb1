// sfx validate SCENE --against embree: checks sfx's BVH hits against Embree 3 on primary and
// diffuse-bounce rays. Exit 0 on pass, 1 on fail, 2 on bad input.
//
// Each --against target is one function below taking the loaded scene and the parsed flags;
// a new target (the stream tracer against the reference tracer) is one more function and one
// more name in k_targets.

#include <cstdio>
#include <cstring>
#include <iostream>
#include <nlohmann/json.hpp>
#include <stdexcept>

#include "app/commands.h"
#include "kernels/bvh.h"
#include "kernels/embree/embree_check.h"
#include "kernels/reference/reference_tracer.h"
#include "kernels/stream/stream_tracer.h"
#include "base/host_clock.h"
#include "base/input_error.h"
#include "workloads/scene_loader.h"

namespace sfx {

namespace {

struct ValidateOptions {
    std::string scene;
    std::string against = "reference";
    uint64_t rays = 1000000;
    float ulps = 16.f;  // embree: agreement tolerance
    bool json = false;
    WorkloadFlags workload;
};

const std::vector<std::string> k_targets = {"reference", "embree"};

std::string format_rate(double r) {
    char buf[32];
    std::snprintf(buf, sizeof buf, "%.2e", r);
    return buf;
}

// Returns true on pass.
bool validate_against_embree(const ValidateOptions& o, const Scene& scene,
                             const RenderSettings& settings, HostClock::time_point start,
                             double load_seconds) {
    // The check holds every ray and hit in memory, ~90 bytes a ray: 10M rays is ~1 GB.
    if (o.rays == 0 || o.rays > 10000000)
        throw InputError("command line", 0, "--rays",
                         "expected 1..10000000, got " + std::to_string(o.rays));
    if (!(o.ulps >= 0.f && o.ulps <= 1e6f))
        throw InputError("command line", 0, "--ulps", "expected 0..1e6, got " + std::to_string(o.ulps));
    const auto bvh_start = HostClock::now();
    const Bvh bvh(scene);
    const double bvh_seconds = seconds_since(bvh_start);

    EmbreeCheckOptions options;
    options.rays = o.rays;
    options.width = settings.width;
    options.height = settings.height;
    options.seed = settings.seed;
    options.threads = settings.threads;
    options.tolerance.ulps = o.ulps;
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
        j["tolerance.ulps"] = o.ulps;
        j["tolerance.relative"] = options.tolerance.relative;
        j["tolerance.edge"] = options.tolerance.edge;
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
    std::printf("%-18s %12llu %12llu %12llu %10s\n", "filtered",
                (unsigned long long)primary.filtered, (unsigned long long)diffuse.filtered,
                (unsigned long long)total.filtered, "");
    std::printf("(* unexplained; filtered: NaN/Inf/out of Embree's range, not traced)\n");
    std::printf("tolerance        %g ulps or %g relative, times 1/|cos| of the hit angle; "
                "edge %g\n", double(options.tolerance.ulps), double(options.tolerance.relative),
                double(options.tolerance.edge));
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

// Checks every traced ray of a few tile passes against the reference traversal of that ray.
struct HitRecordChecker : RayObserver {
    const Bvh& bvh;
    uint64_t checked = 0, mismatches = 0;
    std::vector<std::string> examples;
    explicit HitRecordChecker(const Bvh& b) : bvh(b) {}
    void ray(const PathState& p, const Ray& ray, const Hit& hit, bool occluded) override {
        ++checked;
        bool same;
        if (p.kind == RayKind::shadow) {
            same = bvh.occluded(ray) == occluded;
        } else {
            const Hit ref = bvh.intersect(ray);
            same = ref.prim == hit.prim && float_bits(ref.t) == float_bits(hit.t) &&
                   float_bits(ref.u) == float_bits(hit.u) &&
                   float_bits(ref.v) == float_bits(hit.v);
        }
        if (same) return;
        ++mismatches;
        if (examples.size() < 5)
            examples.push_back("pixel " + std::to_string(p.key.pixel) + " sample " +
                               std::to_string(p.key.sample) + " bounce " +
                               std::to_string(p.bounce));
    }
};

// The stream tracer against the reference tracer: the whole image bit for bit, the ray
// counts, and the per-ray hit records of every ray of up to `o.rays` rays' worth of passes.
bool validate_against_reference(const ValidateOptions& o, const Scene& scene,
                                const RenderSettings& settings, HostClock::time_point start,
                                double load_seconds) {
    const auto bvh_start = HostClock::now();
    const Bvh bvh(scene);
    const double bvh_seconds = seconds_since(bvh_start);
    const RenderResult ref = render_reference(scene, bvh, settings);
    const RenderResult st = render_stream(scene, bvh, settings);
    uint64_t differing = 0;
    std::vector<std::string> pixel_examples;
    for (uint32_t y = 0; y < settings.height; ++y)
        for (uint32_t x = 0; x < settings.width; ++x) {
            const Vec3& a = ref.image.at(x, y);
            const Vec3& b = st.image.at(x, y);
            if (std::memcmp(&a, &b, sizeof(Vec3)) == 0) continue;
            if (++differing <= 5) {
                char buf[160];
                std::snprintf(buf, sizeof buf,
                          "(%u, %u): reference %.9g %.9g %.9g, stream %.9g %.9g %.9g", x, y, a.x,
                          a.y, a.z, b.x, b.y, b.z);
                pixel_examples.push_back(buf);
            }
        }
    const bool same_rays = ref.stats.camera_rays == st.stats.camera_rays &&
                           ref.stats.extension_rays == st.stats.extension_rays &&
                           ref.stats.shadow_rays == st.stats.shadow_rays &&
                           ref.stats.nonfinite_paths == st.stats.nonfinite_paths;
    // Hit records: passes of tiles spread over the image, every ray, until o.rays are checked.
    const auto hits_start = HostClock::now();
    HitRecordChecker checker(bvh);
    const std::vector<TileRect> tiles = make_tiles(settings.width, settings.height, settings.tile);
    StreamTracer tracer(scene, bvh, settings);
    const uint32_t stride = std::max<uint32_t>(1, uint32_t(tiles.size()) / 16);
    for (uint32_t t = 0; t < tiles.size() && checker.checked < o.rays; t += stride)
        for (uint32_t smp = 0; smp < settings.spp && checker.checked < o.rays; ++smp) {
            const TileRect& r = tiles[t];
            std::vector<Vec3> sums(size_t(r.x1 - r.x0) * (r.y1 - r.y0));
            RenderStats stats;
            tracer.trace_pass(r, t, smp, sums.data(), stats, nullptr, &checker);
        }
    const double hits_seconds = seconds_since(hits_start);
    const bool pass = differing == 0 && same_rays && checker.mismatches == 0;
    const double total_seconds = seconds_since(start);
    if (o.json) {
        nlohmann::json j;
        j["scene"] = scene.name;
        j["against"] = o.against;
        j["width"] = settings.width;
        j["height"] = settings.height;
        j["spp"] = settings.spp;
        j["tile"] = settings.tile;
        j["max_depth"] = settings.max_depth;
        j["seed"] = settings.seed;
        j["isa"] = isa_name(settings.isa);
        j["pixels"] = uint64_t(settings.width) * settings.height;
        j["differing_pixels"] = differing;
        j["rays.reference"] = ref.stats.rays();
        j["rays.stream"] = st.stats.rays();
        j["rays.same"] = same_rays;
        j["hit_records.checked"] = checker.checked;
        j["hit_records.mismatches"] = checker.mismatches;
        j["examples.pixels"] = pixel_examples;
        j["examples.hit_records"] = checker.examples;
        j["pass"] = pass;
        j["host_seconds"] = total_seconds;
        j["host_seconds.load"] = load_seconds;
        j["host_seconds.bvh_build"] = bvh_seconds;
        j["host_seconds.reference"] = ref.stats.host_seconds;
        j["host_seconds.stream"] = st.stats.host_seconds;
        j["host_seconds.hit_records"] = hits_seconds;
        std::cout << j.dump(2) << "\n";
        return pass;
    }
    std::printf("scene            %s: %ux%u x %u spp, depth %u, tile %u, seed %llu\n",
                scene.name.c_str(), settings.width, settings.height, settings.spp,
                settings.max_depth, settings.tile, (unsigned long long)settings.seed);
    std::printf("stream back end  %s\n", describe_isa(settings.isa).c_str());
    std::printf("image            %llu of %llu pixels differ in any bit\n",
                (unsigned long long)differing,
                (unsigned long long)(uint64_t(settings.width) * settings.height));
    for (const std::string& e : pixel_examples) std::printf("  %s\n", e.c_str());
    std::printf("rays             reference %llu, stream %llu (%s)\n",
                (unsigned long long)ref.stats.rays(), (unsigned long long)st.stats.rays(),
                same_rays ? "same by kind" : "DIFFER");
    std::printf("hit records      %llu rays checked, %llu differ\n",
                (unsigned long long)checker.checked, (unsigned long long)checker.mismatches);
    for (const std::string& e : checker.examples) std::printf("  %s\n", e.c_str());
    std::printf("result           %s\n", pass ? "PASS (bit-identical)" : "FAIL");
    std::printf("host seconds     %.2f (load %.2f, bvh %.2f, reference %.2f, stream %.2f, "
                "hit records %.2f)\n",
                total_seconds, load_seconds, bvh_seconds, ref.stats.host_seconds,
                st.stats.host_seconds, hits_seconds);
    return pass;
}

}  // namespace

void add_validate_command(CLI::App& app) {
    auto options = std::make_shared<ValidateOptions>();
    CLI::App* c = app.add_subcommand(
        "validate",
        "check sfx against another tracer (reference, the default: the stream tracer's image and "
        "hit records bit for bit against the reference tracer's; embree: Embree 3 on primary and "
        "diffuse rays, classes marked * are unexplained; exit 1 on failure)");
    c->add_option("scene", options->scene, "scene file or built-in scene name")->required();
    c->add_option("--against", options->against,
                  "reference: stream tracer vs reference tracer, bit-exact image and hit records")
        ->check(CLI::IsMember(k_targets))
        ->capture_default_str();
    c->add_option("--rays", options->rays, "rays in total, half primary and half diffuse")
        ->capture_default_str();
    c->add_option("--ulps", options->ulps,
                  "embree: t, u, v agree within this many ulps (of t and of the coordinates) "
                  "or 1e-5 relative")
        ->capture_default_str();
    c->add_flag("--json", options->json, "print one JSON document");
    // --res, --seed and --threads apply; --spp, --depth and --tile are accepted for uniformity
    // with the other commands but do not change the embree check.
    options->workload.add_to(c);
    c->callback([options] {
        const auto start = HostClock::now();
        const Scene scene = load_scene(options->scene);
        const double load_seconds = seconds_since(start);
        const RenderSettings settings = options->workload.resolve(scene);
        bool pass = false;
        if (options->against == "reference")
            pass = validate_against_reference(*options, scene, settings, start, load_seconds);
        if (options->against == "embree")
            pass = validate_against_embree(*options, scene, settings, start, load_seconds);
        if (!pass) throw std::runtime_error("validate: " + options->against + " check failed");
    });
}

}  // namespace sfx
