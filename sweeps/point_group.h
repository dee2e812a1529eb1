#pragma once
// One point group: a scene, a resolution, spp, depth and tile, rendered once by the stream
// tracer, its trace timed on every hardware configuration of the group (trace once, time
// many). This is where the tracer and the hardware model meet; neither knows the other.

#include <functional>
#include <string>
#include <vector>

#include "hw_model/hw_config.h"
#include "hw_model/prediction.h"
#include "hw_model/workload_shape.h"
#include "kernels/bvh.h"
#include "kernels/render.h"
#include "sweeps/sampling.h"
#include "sweeps/workload_config.h"
#include "workloads/scene.h"

namespace sfx {

// What the hardware model needs to know of a workload besides its trace.
WorkloadShape workload_shape(const Scene& scene, const Bvh& bvh, const RenderSettings& settings);
// Per node of `bvh`, whether it is a leaf (WorkloadShape::node_leaf).
std::vector<uint8_t> bvh_leaves(const Bvh& bvh);

struct PointGroupResult {
    std::vector<Prediction> predictions;  // one per configuration, in order
    RenderStats render;                   // the functional render's rays and time
    double host_seconds = 0.0;            // the whole group
    double timing_seconds = 0.0;          // full fidelity: of it, in the cycle-level model's
                                          // pass simulations (the rest: render and counting)
};

// Told (tile passes done, tile passes to do) as the work advances, from one thread at a
// time; the total of a sampled run grows when it adapts to a target error.
using PassProgress = std::function<void(uint64_t done, uint64_t total)>;

// Analytic: the closed form over the whole frame's trace. Full: every tile pass at cycle
// level. Sampled: a stratified sample of tile passes at cycle level (see sweeps/sampling.h),
// extrapolated with a confidence interval on frame cycles.
PointGroupResult run_point_group(const Scene& scene, const Bvh& bvh, const RenderSettings& settings,
                                 const std::vector<HwConfig>& configs, Fidelity fidelity,
                                 const SamplingOptions& sampling = {},
                                 const PassProgress& progress = {});

// Analytic fidelity's pricing of the configurations left out of the calibration sample.
// `varying_parameters`: per configuration, its values of the hardware parameters that differ
// within the group. `uncalibrated_ratios`: each uncalibrated configuration's ratio (cycle
// level / analytic) and relative half-width, from the ratios `r` and half-widths `half` of the
// `calibrated` configurations (indices, ascending); {1, -1} for the calibrated ones. One of
// these rules prices them, whichever predicts the sample best when each calibrated
// configuration is left out in turn (mean squared relative error; ties keep the first):
//  - the sample's mean ratio, with a prediction interval for one more configuration's ratio
//    (Student's t, n - 1 degrees of freedom, over the sample's spread, sqrt(1 + 1/n));
//  - for one parameter p, the mean ratio of the calibrated configurations with the same value
//    of p (a stratum: the unit count, say, when it moves the ratio most), with Student's t
//    times the root mean square of that rule's leave-one-out errors; a configuration whose
//    value no calibrated one has takes the sample's mean.
// Either interval is combined with the calibrated ratios' own sampling error. One calibrated
// configuration gives no spread: its ratio, and its own interval doubled. Choosing the rule on
// the same sample makes its leave-one-out error a little optimistic: the bench
// (bench/analytic_error_bench.cpp) checks the intervals on configurations outside the sample.
std::vector<std::vector<std::string>> varying_parameters(const std::vector<HwConfig>& configs);
std::vector<std::pair<double, double>> uncalibrated_ratios(
    const std::vector<std::vector<std::string>>& knobs, const std::vector<size_t>& calibrated,
    const std::vector<double>& r, const std::vector<double>& half, double confidence);

}  // namespace sfx
