#include <cstdio>
#include <cstdlib>
#include <iostream>

#include "app/commands.h"
#include "hw_model/node_clock.h"
#include "hw_model/tech_table.h"
#include "base/input_error.h"
#include "base/strict_number.h"

namespace sfx {

void WorkloadFlags::add_to(CLI::App* c) {
    c->add_option("--res", res, "image size WxH")->capture_default_str();
    c->add_option("--spp", spp, "samples per pixel")->capture_default_str();
    depth_flag = c->add_option("--depth", depth, "bounces after the camera ray (default: the scene's)");
    c->add_option("--tile", tile, "tile edge in pixels, or auto")->capture_default_str();
    c->add_option("--seed", seed, "random seed")->capture_default_str();
    c->add_option("--threads", threads, "worker threads (0: all cores)")
        ->capture_default_str()
        ->check(CLI::Range(0u, k_max_threads));
    c->add_option("--isa", isa,
                  "host SIMD back end of the stream filters: auto|avx512|avx2|scalar (never "
                  "changes the image or the trace)")
        ->capture_default_str();
    c->add_option("--primary-entry", primary_entry,
                  "where primary-ray streams enter the BVH: root|aepsa (frustum entry-point "
                  "search; never changes the image)")
        ->capture_default_str();
    c->add_option("--reorder", reorder,
                  "sort each generation by approximate hit point before tracing: none|hit_point "
                  "(never changes the image)")
        ->capture_default_str();
    c->add_option("--reorder-lod-ppm", reorder_lod_ppm,
                  "hit_point: simplified geometry, parts per million of the primitives")
        ->capture_default_str();
    c->add_option("--batching", batching,
                  "batch secondary rays in the cells of a top cut of the BVH (RayGrid): "
                  "none|raygrid (never changes the image)")
        ->capture_default_str();
    c->add_option("--batching-queue", batching_queue, "raygrid: rays per queue")
        ->capture_default_str();
    c->add_option("--batching-cell-prims", batching_cell_prims,
                  "raygrid: the most primitives under one cell")
        ->capture_default_str();
}

WorkloadConfig WorkloadFlags::config(const std::string& scene) const {
    WorkloadConfig w;
    w.scene = scene;
    set_workload_field(w, "res", res, "command line", 0, "--res");
    set_workload_field(w, "spp", std::to_string(spp), "command line", 0, "--spp");
    if (depth_flag && depth_flag->count())
        set_workload_field(w, "depth", std::to_string(depth), "command line", 0, "--depth");
    set_workload_field(w, "tile", tile, "command line", 0, "--tile");
    set_workload_field(w, "seed", std::to_string(seed), "command line", 0, "--seed");
    set_workload_field(w, "primary_entry", primary_entry, "command line", 0, "--primary-entry");
    set_workload_field(w, "reorder", reorder, "command line", 0, "--reorder");
    set_workload_field(w, "reorder_lod_ppm", std::to_string(reorder_lod_ppm), "command line", 0,
                       "--reorder-lod-ppm");
    set_workload_field(w, "batching", batching, "command line", 0, "--batching");
    set_workload_field(w, "batching_queue", std::to_string(batching_queue), "command line", 0,
                       "--batching-queue");
    set_workload_field(w, "batching_cell_prims", std::to_string(batching_cell_prims),
                       "command line", 0, "--batching-cell-prims");
    return w;
}

RenderSettings WorkloadFlags::resolve(const Scene& scene,
                                      const std::vector<HwConfig>& configs) const {
    RenderSettings s =
        resolve_workload(config(scene.name), scene.features(), configs, "--tile")
            .config.render_settings(threads);
    s.isa = resolve_isa(parse_isa(isa, "--isa"), "--isa");
    return s;
}

namespace {
double parse_fraction(const std::string& text, const std::string& key) {
    std::string t = text;
    double scale = 1.0;
    if (!t.empty() && t.back() == '%') {
        t.pop_back();
        scale = 0.01;
    }
    double v = 0.0;
    if (!parse_finite(t, v) || !(v * scale > 0.0) || v * scale > 1.0)
        throw InputError("command line", 0, key, "expected a fraction in (0, 1] or a percentage, got '" + text + "'");
    return v * scale;
}
}  // namespace

void SamplingFlags::add_to(CLI::App* c) {
    c->add_option("--sample-fraction", fraction, "sampled fidelity: share of tile passes timed")
        ->capture_default_str();
    c->add_option("--target-error", target_error,
                  "sampled fidelity: sample until the interval's relative half-width is below this");
    c->add_option("--confidence", confidence, "sampled fidelity: two-sided confidence level")
        ->capture_default_str();
    c->add_option("--warmup-passes", warmup_passes, "sampled fidelity: passes replayed into the caches first")
        ->capture_default_str();
    c->add_option("--warm-frames", warm_frames,
                  "full fidelity: renders of the workload's other frames (seeds after --seed) into "
                  "the scene caches before the timed frame (0: it starts from empty caches)")
        ->capture_default_str();
    c->add_option("--strata", strata, "sampled fidelity: strata of tiles")->capture_default_str();
    c->add_option("--calibration", calibration,
                  "analytic fidelity: share of passes also timed at cycle level to calibrate it "
                  "(0: uncalibrated, error unknown)")
        ->capture_default_str();
}

SamplingOptions SamplingFlags::resolve(uint64_t seed) const {
    SamplingOptions o;
    o.fraction = parse_fraction(fraction, "--sample-fraction");
    if (!target_error.empty()) o.target_error = parse_fraction(target_error, "--target-error");
    o.confidence = parse_fraction(confidence, "--confidence");
    if (o.confidence >= 1.0) throw InputError("command line", 0, "--confidence", "must be below 100%");
    if (strata == 0) throw InputError("command line", 0, "--strata", "must be at least 1");
    o.calibration_fraction = calibration == "0" || calibration == "0%"
                                 ? 0.0
                                 : parse_fraction(calibration, "--calibration");
    o.warmup_passes = warmup_passes;
    o.warm_frames = warm_frames;
    o.strata = strata;
    o.seed = seed + 1;
    return o;
}

void add_tech_option(CLI::App* command, std::string& tech) {
    std::string names;
    for (const std::string& n : builtin_tech_names()) names += (names.empty() ? "" : ", ") + n;
    command->add_option("--tech", tech,
                        "technology node of every configuration: a built-in table (" + names +
                            ") or a *.tech.yaml file; it prices area and energy and sets the "
                            "clocks a configuration does not write (default: each "
                            "configuration's tech.node, 90nm in the presets)");
}

void apply_tech_option(std::vector<HwConfig>& configs, const std::string& tech) {
    if (!tech.empty()) {
        tech_table_for(tech, "--tech");
        for (HwConfig& c : configs) c.tech.node = tech;
    }
    for (HwConfig& c : configs)
        for (const std::string& w : resolve_node_clocks(c)) std::cerr << "warning: " << w << "\n";
}

}  // namespace sfx
