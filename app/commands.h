#pragma once
// The sfx subcommands. Each add_*_command registers one subcommand; main.cpp lists them.
// Commands print a human table by default and one JSON document with --json.

#include <CLI/CLI.hpp>
#include <string>

#include "kernels/render.h"
#include "sweeps/sampling.h"
#include "sweeps/workload_config.h"
#include "workloads/scene.h"

namespace sfx {

// Workload flags shared by every command that renders or simulates a scene.
struct WorkloadFlags {
    std::string res = "256x256";
    uint32_t spp = 4;
    uint32_t depth = 0;  // used only when --depth is given; else the scene's own max_depth
    const CLI::Option* depth_flag = nullptr;
    std::string tile = "32";
    uint64_t seed = 0;
    uint32_t threads = 0;
    std::string isa = "auto";
    std::string primary_entry = "root";
    std::string reorder = "none";
    uint32_t reorder_lod_ppm = 20000;
    std::string batching = "none";
    uint32_t batching_queue = 384;
    uint32_t batching_cell_prims = 4096;

    void add_to(CLI::App* command);
    // The workload the flags give for `scene`; throws InputError (key = the flag) on a bad value.
    WorkloadConfig config(const std::string& scene) const;
    // Resolved against the scene and the configurations the command times (resolve_workload:
    // the scene's depth, tile auto, the tile checked against every configuration).
    RenderSettings resolve(const Scene& scene, const std::vector<HwConfig>& configs = {}) const;
};

// Sampling flags shared by the commands that predict at sampled fidelity.
struct SamplingFlags {
    std::string fraction = "2%";
    std::string target_error;  // empty: sample `fraction` of the passes
    std::string confidence = "99.7%";
    uint32_t warmup_passes = 1;
    uint32_t warm_frames = 0;
    uint32_t strata = 8;
    std::string calibration = "2%";  // analytic fidelity: passes also timed at cycle level

    void add_to(CLI::App* command);
    // Throws InputError (key = the flag) on a bad value. "2%" and "0.02" mean the same.
    SamplingOptions resolve(uint64_t seed) const;
};

// --tech NAME|FILE: the technology node (a built-in table name or a *.tech.yaml file) of every
// configuration the command times; not given: each configuration's own `tech.node`.
void add_tech_option(CLI::App* command, std::string& tech);
// Sets every configuration's node to `tech` (unless empty), then its clocks to those the node
// allows where the configuration does not write them (hw_model/node_clock.h), printing a
// warning to stderr for a written clock above its critical path's.
void apply_tech_option(std::vector<HwConfig>& configs, const std::string& tech);

void add_render_command(CLI::App& app);
void add_trace_stats_command(CLI::App& app);
void add_validate_command(CLI::App& app);
void add_scene_info_command(CLI::App& app);
void add_simulate_command(CLI::App& app);
void add_accuracy_command(CLI::App& app);
void add_sweep_command(CLI::App& app);  // also the hidden run-group
void add_explore_command(CLI::App& app);
void add_compare_command(CLI::App& app);
void add_report_command(CLI::App& app);
void add_calibrate_command(CLI::App& app);  // --describe-host, --check

// After every command is added: each number flag must be plain decimal text in its type's
// range (no sign wrapping, clamping, octal, hex, NaN or infinity).
void strict_number_flags(CLI::App& app);

}  // namespace sfx
