// sfx simulate HW.hw.yaml [HW2.hw.yaml ...] --scene SCENE: predicted fps, utilization, stalls
// and operation mix. Several configurations share one functional render (trace once, time many).

#include <iomanip>
#include <iostream>
#include <nlohmann/json.hpp>
#include <sstream>

#include "app/commands.h"
#include "app/progress.h"
#include "kernels/bvh.h"
#include "sweeps/point_group.h"
#include "base/input_error.h"
#include "workloads/scene_loader.h"

namespace sfx {

nlohmann::json prediction_json(const Prediction& p, const ConfigLabel& label) {
    nlohmann::json j;
    j["config"] = p.config.name;
    j["label"] = label.name;
    j["differs_from_first"] = label.differences;
    j["fidelity"] = to_string(p.fidelity);
    j["simd_width"] = p.config.simd.width;
    for (const Stat& s : p.stats()) j[s.name] = s.value;
    return j;
}

void print_predictions(const std::vector<Prediction>& predictions,
                       const std::vector<ConfigLabel>& labels, std::ostream& out) {
    if (predictions.size() > 1) {
        // The table's columns are narrow: the labels, and what sets each apart, come first.
        out << "configurations (and the parameters in which each differs from the first):\n";
        for (size_t i = 0; i < labels.size(); ++i) {
            out << "  " << labels[i].name;
            for (size_t k = 0; k < labels[i].differences.size(); ++k)
                out << (k ? ", " : "  ") << labels[i].differences[k];
            if (i > 0 && labels[i].differences.empty()) out << "  (the same parameters)";
            out << "\n";
        }
        out << "\n";
    }
    auto row = [&](const std::string& label, auto value_of) {
        out << std::left << std::setw(38) << label;
        for (const Prediction& p : predictions) out << std::right << std::setw(16) << value_of(p);
        out << "\n";
    };
    auto stat = [](const Prediction& p, const std::string& name) {
        for (const Stat& s : p.stats())
            if (s.name == name) return s.value;
        return 0.0;
    };
    auto fixed = [](double v, int digits) {
        std::ostringstream s;
        s << std::fixed << std::setprecision(digits) << v;
        return s.str();
    };
    size_t column = 0;
    row("configuration", [&](const Prediction&) {
        const std::string& n = labels[column++].name;
        return n.size() > 15 ? n.substr(0, 14) + "~" : n;
    });
    row("fidelity", [](const Prediction& p) { return std::string(to_string(p.fidelity)); });
    row("simd width", [](const Prediction& p) { return std::to_string(p.config.simd.width); });
    row("tile", [](const Prediction& p) { return std::to_string(p.tile); });
    row("fps", [&](const Prediction& p) { return fixed(p.fps(), 3); });
    row("fps, stalls hidden", [&](const Prediction& p) { return fixed(stat(p, "fps_stall_free"), 3); });
    row("fps, stalls hidden, lanes full",
        [&](const Prediction& p) { return fixed(stat(p, "fps_stall_free_full_lanes"), 3); });
    row("frame cycles", [&](const Prediction& p) { return std::to_string(p.timing.cycles); });
    for (const char* stage : {"traversal", "intersection", "shading"}) {
        row(std::string("utilization ") + stage + " (ideal)", [&](const Prediction& p) {
            return fixed(100 * stat(p, std::string("simd_utilization.") + stage), 1) + "% (" +
                   fixed(100 * stat(p, std::string("ideal_simd_utilization.") + stage), 1) + "%)";
        });
    }
    for (const char* stage : {"traversal", "intersection", "shading"}) {
        row(std::string("stream length ") + stage, [&](const Prediction& p) {
            return fixed(stat(p, std::string("stream_length.") + stage), 1);
        });
    }
    row("option overhead (% of instructions)",
        [&](const Prediction& p) { return fixed(stat(p, "op_mix.option_percent"), 2); });
    row("box tests per ray (prim / sec)", [&](const Prediction& p) {
        return fixed(p.box_tests_per_ray[0], 1) + " / " + fixed(p.box_tests_per_ray[1], 1);
    });
    row("primary entry depth", [&](const Prediction& p) { return fixed(p.entry_depth, 2); });
    for (uint32_t g = 1; g < Prediction::k_bounces; ++g)
        row("bounce " + std::to_string(g) + " rays/node, /leaf, box/ray", [&](const Prediction& p) {
            return fixed(p.rays_per_node[g], 1) + " / " + fixed(p.rays_per_leaf[g], 1) + ", " +
                   fixed(p.bounce_box_tests_per_ray[g], 1);
        });
    row("raygrid queue length (full %)", [&](const Prediction& p) {
        return fixed(p.batch_mean_queue, 1) + " (" + fixed(100 * p.batch_full_share, 0) + "%)";
    });
    for (const char* cause : {"bank_conflict", "alignment", "address_fetch", "partition",
                              "scene_memory", "interconnect", "pipeline_fill"}) {
        row(std::string("stall ") + cause + " (% of cycles)", [&](const Prediction& p) {
            return fixed(100 * stat(p, std::string("stall_cycles.") + cause) /
                             std::max(1.0, double(p.timing.cycles)), 1);
        });
    }
    for (const char* m : {"load", "store", "compute", "scatter_gather", "partition"}) {
        row(std::string("op mix ") + m + " %", [&](const Prediction& p) {
            return fixed(stat(p, std::string("op_mix.") + m + "_percent"), 1);
        });
    }
    row("bank conflict rate", [&](const Prediction& p) {
        return fixed(100 * stat(p, "ray_buffer.bank_conflict_rate"), 2) + "%";
    });
    for (size_t level = 0; level < predictions.front().config.scene_memory.caches.size(); ++level) {
        const std::string name = predictions.front().config.scene_memory.caches[level].name;
        row("scene cache " + name + " hit rate (misses)", [&](const Prediction& p) {
            return fixed(100 * stat(p, "scene_cache." + name + ".hit_rate"), 1) + "% (" +
                   fixed(stat(p, "scene_cache." + name + ".misses"), 0) + ")";
        });
    }
    // Area and energy per unit (the technology table's node), then the totals.
    for (const Stat& s : predictions.front().stats()) {
        const bool area = s.name.rfind("area.", 0) == 0, energy = s.name.rfind("energy.", 0) == 0;
        if (!area && !energy) continue;
        const std::string what = s.name.substr(s.name.find('.') + 1);
        const std::string label = area ? "area " + what.substr(0, what.size() - 4) + " mm2"
                                       : "energy " + what.substr(0, what.size() - 13) + " mJ/frame";
        row(label, [&](const Prediction& p) { return fixed(stat(p, s.name), 3); });
    }
    row("power W (static W)", [&](const Prediction& p) {
        return fixed(stat(p, "power.w"), 3) + " (" + fixed(stat(p, "power.leakage_w"), 3) + ")";
    });
    // Per unit: dynamic power (static power in brackets; DRAM has none on chip).
    for (const Stat& s : predictions.front().stats()) {
        const size_t end = s.name.rfind(".dynamic_w");
        if (s.name.rfind("power.", 0) != 0 || end == std::string::npos) continue;
        const std::string unit = s.name.substr(6, end - 6);
        row("power " + unit + " W (static W)", [&](const Prediction& p) {
            const double leak = stat(p, "power." + unit + ".static_w");
            return fixed(stat(p, s.name), 3) + (unit == "dram" ? "" : " (" + fixed(leak, 3) + ")");
        });
    }
    row("fps per mm2", [&](const Prediction& p) { return fixed(stat(p, "fps_per_mm2"), 4); });
    row("frames per joule", [&](const Prediction& p) { return fixed(stat(p, "frames_per_joule"), 2); });
    row("technology node nm", [&](const Prediction& p) { return fixed(stat(p, "tech.node_nm"), 0); });
    row("clock core / interconnect MHz", [&](const Prediction& p) {
        return fixed(p.config.clock.core_mhz, 0) + " / " + fixed(p.config.clock.interconnect_mhz, 0);
    });
    row("host seconds", [&](const Prediction& p) { return fixed(p.host_seconds, 3); });
    row("error estimate (interval)", [&](const Prediction& p) {
        return p.error_relative < 0 ? std::string("unknown") : "+-" + fixed(100 * p.error_relative, 2) + "%";
    });
    row("tile passes timed", [&](const Prediction& p) {
        return std::to_string(p.sample_passes) + "/" + std::to_string(p.total_passes);
    });
}

void add_simulate_command(CLI::App& app) {
    struct Options {
        std::vector<std::string> hw;
        std::string scene;
        std::string fidelity = "full";
        std::string tech;
        bool json = false;
        WorkloadFlags workload;
        SamplingFlags sampling;
    };
    auto o = std::make_shared<Options>();
    CLI::App* c = app.add_subcommand("simulate", "predict frame rate and utilization of hardware configurations");
    c->add_option("hw", o->hw, "hardware configuration files (*.hw.yaml) or preset names (gr08, ...); several share one render")
        ->required();
    c->add_option("--scene", o->scene, "scene file or built-in scene name")->required();
    c->add_option("--fidelity", o->fidelity, "analytic | sampled | full")
        ->check(CLI::IsMember({"analytic", "sampled", "full"}))
        ->capture_default_str();
    c->add_flag("--json", o->json, "print one JSON document (a list for several configurations)");
    add_tech_option(c, o->tech);
    o->workload.add_to(c);
    o->sampling.add_to(c);
    c->callback([o] {
        std::vector<HwConfig> configs;
        for (const std::string& path : o->hw) configs.push_back(load_hw_config(path));
        apply_tech_option(configs, o->tech);
        const std::vector<ConfigLabel> labels = label_configs(configs, o->hw);
        const Scene scene = load_scene(o->scene);
        const RenderSettings settings = o->workload.resolve(scene, configs);
        const Bvh bvh(scene);
        Progress progress("simulate", 0, "tile passes");
        progress.set_label(o->fidelity + " fidelity, " + std::to_string(configs.size()) +
                           (configs.size() == 1 ? " configuration" : " configurations"));
        PointGroupResult r =
            run_point_group(scene, bvh, settings, configs, parse_fidelity(o->fidelity),
                            o->sampling.resolve(settings.seed), [&](uint64_t done, uint64_t total) {
                                progress.set_total(total);
                                progress.set_done(done);
                            });
        progress.finish();
        if (o->json) {
            if (r.predictions.size() == 1) {
                std::cout << prediction_json(r.predictions[0], labels[0]).dump(2) << "\n";
            } else {
                nlohmann::json list = nlohmann::json::array();
                for (size_t i = 0; i < r.predictions.size(); ++i)
                    list.push_back(prediction_json(r.predictions[i], labels[i]));
                std::cout << list.dump(2) << "\n";
            }
            return;
        }
        std::cout << "scene " << scene.name << ", " << settings.width << "x" << settings.height
                  << " x " << settings.spp << " spp, depth " << settings.max_depth << ", tile "
                  << settings.tile << ", " << r.render.rays() << " rays, stream back end "
                  << describe_isa(settings.isa) << "\n\n";
        print_predictions(r.predictions, labels, std::cout);
        std::cout << "\nhost seconds for the group: " << r.host_seconds;
        if (r.timing_seconds > 0.0)
            std::cout << " (timing model " << r.timing_seconds << ", render and the rest "
                      << r.host_seconds - r.timing_seconds << ")";
        std::cout << "\n";
    });
}

}  // namespace sfx
