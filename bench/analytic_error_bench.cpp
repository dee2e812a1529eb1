// The analytic level's error against the cycle-level model, and whether the error each analytic
// point states covers it: a grid of 24 configurations (SIMD widths 4/8/16 x units 1/2 x banks
// 16/32 x ray buffers 256/512 KiB) timed at analytic and at full fidelity on the same render,
// per scene. The analytic group calibrates a systematic sample of 8 of its 24 configurations at
// cycle level (sweeps/point_group.cpp); the other 16 take a ratio and interval from the sample
// (uncalibrated_ratios, sweeps/point_group.h): they are the check on those intervals.
// Prints each configuration's error and stated interval, then the distribution of |error|
// (median, 90th percentile, worst), how many stated intervals cover their error, and the host
// time of each level.
// Usage: sfx_bench_analytic_error [WxH] [spp] [scene ...]   (default 128x128 1 conference atrium)

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <string>
#include <vector>

#include "kernels/bvh.h"
#include "sweeps/point_group.h"
#include "workloads/scene_loader.h"

using namespace sfx;

namespace {

double percentile(std::vector<double> v, double q) {
    std::sort(v.begin(), v.end());
    return v[std::min(v.size() - 1, size_t(q * double(v.size())))];
}

}  // namespace

// libsystemc.so defines main() and calls sc_main(); this bench has its own main().
extern "C" int sc_main(int, char**) { return 0; }

int main(int argc, char** argv) {
    setenv("SC_COPYRIGHT_MESSAGE", "DISABLE", 1);
    const std::string res = argc > 1 ? argv[1] : "128x128";
    const uint32_t spp = argc > 2 ? uint32_t(std::atoi(argv[2])) : 1;
    std::vector<std::string> scenes;
    for (int i = 3; i < argc; ++i) scenes.push_back(argv[i]);
    if (scenes.empty()) scenes = {"conference", "atrium"};

    std::vector<HwConfig> configs;
    std::vector<std::string> names;
    for (uint32_t width : {4u, 8u, 16u})
        for (uint32_t units : {1u, 2u})
            for (uint32_t banks : {16u, 32u})
                for (uint32_t kib : {256u, 512u}) {
                    HwConfig c;
                    c.simd.width = width;
                    c.simd.units = units;
                    c.ray_buffer.banks = banks;
                    c.agu.count = banks;
                    c.ray_buffer.kib = kib;
                    configs.push_back(c);
                    names.push_back("w" + std::to_string(width) + " u" + std::to_string(units) + " b" +
                                    std::to_string(banks) + " " + std::to_string(kib) + "K");
                }
    std::vector<double> all_errors;
    size_t all_covered = 0;
    for (const std::string& name : scenes) {
        const Scene scene = load_scene(name);
        const Bvh bvh(scene);
        RenderSettings settings;
        std::sscanf(res.c_str(), "%ux%u", &settings.width, &settings.height);
        settings.spp = spp;
        settings.tile = 32;
        settings.max_depth = scene.max_depth;
        settings.threads = 1;
        const PointGroupResult analytic = run_point_group(scene, bvh, settings, configs, Fidelity::analytic);
        const PointGroupResult full = run_point_group(scene, bvh, settings, configs, Fidelity::full);
        std::printf("%s %ux%u x %u spp, tile %u: %zu configurations\n", name.c_str(), settings.width,
                    settings.height, spp, settings.tile, configs.size());
        std::printf("  %-16s %12s %12s %9s %9s %s\n", "configuration", "analytic fps", "full fps",
                    "error", "stated", "");
        std::vector<double> errors;
        size_t covered = 0;
        for (size_t c = 0; c < configs.size(); ++c) {
            const Prediction& a = analytic.predictions[c];
            const Prediction& f = full.predictions[c];
            const double error = a.fps() / f.fps() - 1.0;
            // The interval is on frame cycles; fps = clock / cycles, so compare on cycles.
            const double cycle_error = double(a.timing.cycles) / double(f.timing.cycles) - 1.0;
            const bool ok = a.error_relative >= 0.0 && std::fabs(cycle_error) <= a.error_relative;
            covered += ok;
            errors.push_back(std::fabs(error));
            std::printf("  %-16s %12.4f %12.4f %+8.2f%% %8.2f%% %s%s\n", names[c].c_str(), a.fps(), f.fps(),
                        100 * error, 100 * a.error_relative, ok ? "covered" : "NOT covered",
                        a.sample_passes ? " (calibrated)" : "");
        }
        std::printf("  |error|: median %.2f %%, 90th percentile %.2f %%, worst %.2f %%; stated interval "
                    "covers %zu of %zu\n",
                    100 * percentile(errors, 0.5), 100 * percentile(errors, 0.9),
                    100 * *std::max_element(errors.begin(), errors.end()), covered, errors.size());
        std::printf("  host seconds: analytic group %.2f, full group %.2f (%.1fx)\n\n", analytic.host_seconds,
                    full.host_seconds, full.host_seconds / analytic.host_seconds);
        all_errors.insert(all_errors.end(), errors.begin(), errors.end());
        all_covered += covered;
    }
    std::printf("all scenes: |error| median %.2f %%, 90th percentile %.2f %%, worst %.2f %%; covered %zu of %zu\n",
                100 * percentile(all_errors, 0.5), 100 * percentile(all_errors, 0.9),
                100 * *std::max_element(all_errors.begin(), all_errors.end()), all_covered, all_errors.size());
    return 0;
}
