#include "sweeps/host_time_estimate.h"

#include <algorithm>
#include <cmath>

#include "sweeps/sampling.h"

namespace sfx {

namespace {

// CPU seconds per unit of work (one path-bounce through one level of the BVH), fitted on
// cornell, conference and atrium at 128x128 x 1 spp, tile 32, with 1 and 4 configurations per
// group (the sweeps and figures are in sweeps/README.md): the render once per group, the
// timing once per point. Per scene the fitted rates spread by about 2x around these.
constexpr double k_render_rate = 6.5e-8;
constexpr double k_analytic_rate = 5e-9;
constexpr double k_full_rate = 6.7e-7;
// CPU seconds of the sweep machinery per point, whatever the frame: its key, the worker's parse,
// its row's write. bench/scale-analytic.sweep.yaml's first 40 seeds (2560 analytic points of a
// 32x32 cornell frame, whose model work the rates above put at 0.3 s) took 7.2 s of CPU.
constexpr double k_point_overhead = 2.7e-3;

double work_units(const PointGroup& g) {
    const WorkloadConfig& w = g.workload;
    return double(w.width) * double(w.height) * double(w.spp) * double(w.depth + 1) *
           std::log2(double(g.scene_primitives) + 2.0);
}

// Sampled fidelity times its sample of tile passes (at least two per stratum), each after a
// warm-up pass, at the full rate.
double sampled_share(const WorkloadConfig& w) {
    const SamplingOptions opt;
    const double tiles = std::ceil(double(w.width) / w.tile) * std::ceil(double(w.height) / w.tile);
    const double units = tiles * w.spp;
    const double sampled = std::max(2.0 * opt.strata, std::ceil(opt.fraction * units));
    return std::min(1.0, sampled * (1.0 + opt.warmup_passes) / units);
}

double point_seconds(const PointGroup& g) {
    const double work = work_units(g);
    switch (g.fidelity) {
        case Fidelity::analytic: return k_analytic_rate * work;
        case Fidelity::sampled: return k_full_rate * work * sampled_share(g.workload);
        case Fidelity::full: return k_full_rate * work;
    }
    return 0;
}

}  // namespace

const char* const k_estimate_basis =
    "rates of a 2-core AMD EPYC host, AVX2, good to about 2x";

std::vector<FidelityEstimate> estimate_host_seconds(const Sweep& sweep) {
    std::vector<FidelityEstimate> out;
    for (Fidelity f : {Fidelity::analytic, Fidelity::sampled, Fidelity::full}) {
        FidelityEstimate e;
        e.fidelity = f;
        for (const PointGroup& g : sweep.groups) {
            if (g.fidelity != f) continue;
            ++e.groups;
            e.points += g.points.size();
            e.seconds += k_render_rate * work_units(g) +
                         (k_point_overhead + point_seconds(g)) * double(g.points.size());
        }
        if (e.groups) out.push_back(e);
    }
    return out;
}

}  // namespace sfx
