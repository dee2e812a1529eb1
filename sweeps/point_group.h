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

}  // namespace sfx
