// sfx accuracy HW.hw.yaml --scene SCENE: the same point at every fidelity, host time against
// error. Each row is obtained from scratch (its own functional render), so its host seconds
// are what that fidelity costs.

#include <cmath>
#include <cstdio>
#include <fstream>
#include <iomanip>
#include <iostream>
#include <nlohmann/json.hpp>
#include <sstream>

#include "app/commands.h"
#include "app/progress.h"
#include "kernels/bvh.h"
#include "sweeps/point_group.h"
#include "base/input_error.h"
#include "base/user_files.h"
#include "workloads/scene_loader.h"

#ifndef SFX_ACCURACY_PLOT
#define SFX_ACCURACY_PLOT ""
#endif

namespace sfx {

namespace {

struct AccuracyRow {
    std::string fidelity;
    double sample_fraction = 1.0;
    double target_error = 0.0;
    Prediction prediction;
};

void write_plot(const nlohmann::json& rows, const std::string& png) {
    const std::string data = png + ".json";
    {
        std::ofstream out(data);
        out << rows.dump();
    }
    const std::string command = std::string("/usr/bin/python3 '") + SFX_ACCURACY_PLOT + "' '" +
                                data + "' '" + png + "'";
    const int status = std::system(command.c_str());
    std::remove(data.c_str());
    if (status != 0) throw std::runtime_error("plotting failed: " + command);
}

}  // namespace

void add_accuracy_command(CLI::App& app) {
    struct Options {
        std::string hw;
        std::string scene;
        bool json = false;
        std::string plot;
        std::string tech;
        WorkloadFlags workload;
        SamplingFlags sampling;
    };
    auto o = std::make_shared<Options>();
    CLI::App* c = app.add_subcommand(
        "accuracy", "one point at analytic, sampled (1, 2, 5, 10 %, adaptive to 2 %) and full fidelity");
    c->add_option("hw", o->hw, "hardware configuration file (*.hw.yaml) or preset name (gr08, ...)")->required();
    c->add_option("--scene", o->scene, "scene file or built-in scene name")->required();
    c->add_flag("--json", o->json, "print a JSON list of rows");
    c->add_option("--plot", o->plot, "also draw error against host time into this PNG");
    add_tech_option(c, o->tech);
    o->workload.add_to(c);
    o->sampling.add_to(c);
    c->callback([o] {
        std::vector<HwConfig> configs = {load_hw_config(o->hw)};
        apply_tech_option(configs, o->tech);
        const Scene scene = load_scene(o->scene);
        const RenderSettings settings = o->workload.resolve(scene, configs);
        if (!o->plot.empty() && (o->plot.size() < 5 || o->plot.substr(o->plot.size() - 4) != ".png"))
            throw InputError("command line", 0, "--plot", "expected a .png path, got '" + o->plot + "'");
        if (!o->plot.empty()) check_output_file(o->plot, "--plot");
        const Bvh bvh(scene);
        SamplingOptions base = o->sampling.resolve(settings.seed);
        base.target_error = 0.0;

        std::vector<AccuracyRow> rows;
        const size_t levels = 7;  // the run() calls below
        auto run = [&](const std::string& name, Fidelity f, const SamplingOptions& s) {
            // Each level from scratch: its own bar, in the tile passes it traces.
            Progress progress("accuracy", 0, "tile passes");
            progress.set_label(name + " (" + std::to_string(rows.size() + 1) + "/" +
                               std::to_string(levels) + ")");
            AccuracyRow row;
            row.fidelity = name;
            row.sample_fraction = s.fraction;
            row.target_error = s.target_error;
            row.prediction = run_point_group(scene, bvh, settings, configs, f, s,
                                             [&](uint64_t done, uint64_t total) {
                                                 progress.set_total(total);
                                                 progress.set_done(done);
                                             })
                                 .predictions[0];
            progress.finish();
            // The share of tile passes timed at cycle level (analytic: its calibration sample).
            row.sample_fraction = double(row.prediction.sample_passes) /
                                  double(std::max<uint64_t>(1, row.prediction.total_passes));
            rows.push_back(row);
        };
        run("analytic", Fidelity::analytic, base);  // calibrated on base.calibration_fraction
        for (double fraction : {0.01, 0.02, 0.05, 0.10}) {
            SamplingOptions s = base;
            s.fraction = fraction;
            std::ostringstream name;
            name << "sampled " << fraction * 100 << "%";
            run(name.str(), Fidelity::sampled, s);
        }
        SamplingOptions adaptive = base;
        adaptive.fraction = 0.01;
        adaptive.target_error = 0.02;
        run("sampled to 2%", Fidelity::sampled, adaptive);
        run("full", Fidelity::full, base);

        const Prediction& full = rows.back().prediction;
        nlohmann::json list = nlohmann::json::array();
        for (const AccuracyRow& r : rows) {
            const Prediction& p = r.prediction;
            nlohmann::json j;
            j["fidelity"] = r.fidelity;
            j["sample_fraction"] = r.sample_fraction;
            j["passes.timed"] = p.sample_passes;
            j["passes.total"] = p.total_passes;
            j["host_seconds"] = p.host_seconds;
            j["speedup"] = p.host_seconds > 0 ? full.host_seconds / p.host_seconds : 0.0;
            j["fps"] = p.fps();
            j["frame_cycles"] = p.timing.cycles;
            j["error.relative"] = p.error_relative;  // the interval's half-width, or -1
            j["error.actual"] = full.timing.cycles ? (double(p.timing.cycles) - double(full.timing.cycles)) /
                                                          double(full.timing.cycles)
                                                    : 0.0;
            list.push_back(j);
        }
        if (!o->plot.empty()) write_plot(list, o->plot);
        if (o->json) {
            std::cout << list.dump(2) << "\n";
            return;
        }
        std::cout << "scene " << scene.name << ", " << settings.width << "x" << settings.height << " x "
                  << settings.spp << " spp, tile " << settings.tile << ", " << configs[0].name
                  << " (width " << configs[0].simd.width << ")\n\n";
        std::cout << std::left << std::setw(16) << "fidelity" << std::right << std::setw(10) << "passes"
                  << std::setw(12) << "host s" << std::setw(10) << "speed-up" << std::setw(12) << "fps"
                  << std::setw(12) << "interval" << std::setw(14) << "error vs full" << "\n";
        for (const auto& j : list) {
            std::ostringstream passes, interval, error;
            passes << std::fixed << std::setprecision(1) << 100.0 * j["sample_fraction"].get<double>() << "%";
            const double rel = j["error.relative"].get<double>();
            if (rel < 0) interval << "unknown";
            else interval << "+-" << std::fixed << std::setprecision(2) << 100 * rel << "%";
            error << std::showpos << std::fixed << std::setprecision(2) << 100 * j["error.actual"].get<double>() << "%";
            std::cout << std::left << std::setw(16) << j["fidelity"].get<std::string>() << std::right
                      << std::setw(10) << passes.str() << std::setw(12) << std::fixed << std::setprecision(3)
                      << j["host_seconds"].get<double>() << std::setw(9) << std::setprecision(1)
                      << j["speedup"].get<double>() << "x" << std::setw(12) << std::setprecision(3)
                      << j["fps"].get<double>() << std::setw(12) << interval.str() << std::setw(14)
                      << error.str() << "\n";
        }
        if (!o->plot.empty()) std::cout << "\nwrote " << o->plot << "\n";
    });
}

}  // namespace sfx
