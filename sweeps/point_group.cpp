#include "sweeps/point_group.h"

#include <chrono>
#include <cmath>

#include "hw_model/analytic_model.h"
#include "hw_model/systemc/systemc_timing.h"
#include "kernels/stream/stream_tracer.h"
#include "workloads/input_error.h"
#include "workloads/ray_layout.h"

namespace sfx {
namespace {

// Forwards every trace call to several sinks.
class FanOutSink : public TraceSink {
public:
    void add(TraceSink* s) { m_sinks.push_back(s); }
    void begin_frame(const TraceHeader& h) override { for (auto* s : m_sinks) s->begin_frame(h); }
    void begin_pass(const TilePass& p) override { for (auto* s : m_sinks) s->begin_pass(p); }
    void op(const StreamOp& o) override { for (auto* s : m_sinks) s->op(o); }
    void end_pass(const TilePass& p) override { for (auto* s : m_sinks) s->end_pass(p); }
    void end_frame() override { for (auto* s : m_sinks) s->end_frame(); }

private:
    std::vector<TraceSink*> m_sinks;
};

double seconds_since(std::chrono::steady_clock::time_point start) {
    return std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
}

}  // namespace

uint32_t largest_fitting_tile(const FeatureSet& features, const std::vector<HwConfig>& configs) {
    const uint64_t bytes_per_ray = ray_record_bytes(features);
    uint64_t smallest = UINT64_MAX;
    for (const HwConfig& c : configs) smallest = std::min<uint64_t>(smallest, uint64_t(c.ray_buffer.kib) * 1024);
    return uint32_t(std::sqrt(double(smallest / bytes_per_ray)));
}

void check_tile_fits(uint32_t tile, const FeatureSet& features,
                     const std::vector<HwConfig>& configs, const std::string& key) {
    const uint64_t need = uint64_t(tile) * tile * ray_record_bytes(features);
    for (const HwConfig& c : configs)
        if (need > uint64_t(c.ray_buffer.kib) * 1024)
            throw InputError("command line", 0, key,
                             "a " + std::to_string(tile) + "x" + std::to_string(tile) +
                                 " stream needs " + std::to_string((need + 1023) / 1024) +
                                 " KiB of ray data; configuration '" + c.name + "' has " +
                                 std::to_string(c.ray_buffer.kib) + " KiB buffers (largest tile: " +
                                 std::to_string(largest_fitting_tile(features, {c})) + ")");
}

PointGroupResult run_point_group(const Scene& scene, const Bvh& bvh,
                                 const RenderSettings& settings,
                                 const std::vector<HwConfig>& configs, Fidelity fidelity) {
    if (fidelity == Fidelity::sampled)
        throw InputError("command line", 0, "--fidelity",
                         "sampled fidelity is not available yet; use analytic or full");
    const auto start = std::chrono::steady_clock::now();
    WorkloadShape shape;
    shape.features = scene.features();
    shape.features.max_depth = settings.max_depth;
    shape.triangles = scene.triangles.size();
    shape.spheres = scene.spheres.size();
    shape.bvh_nodes = bvh.nodes().size();
    shape.tile = settings.tile;
    check_tile_fits(settings.tile, shape.features, configs, "--tile");

    std::vector<uint32_t> widths;
    for (const HwConfig& c : configs) widths.push_back(c.simd.width);
    CountingSink counts(widths);
    FanOutSink fan;
    fan.add(&counts);
    TraceProfile profile(shape);
    std::unique_ptr<SystemcTiming> systemc;
    if (fidelity == Fidelity::analytic) {
        fan.add(&profile);
    } else {
        systemc = std::make_unique<SystemcTiming>(configs, shape);
        fan.add(systemc.get());
    }
    PointGroupResult result;
    result.render = render_stream(scene, bvh, settings, &fan).stats;
    const double shared_seconds = seconds_since(start);

    for (size_t i = 0; i < configs.size(); ++i) {
        const auto model_start = std::chrono::steady_clock::now();
        Prediction p;
        p.config = configs[i];
        p.fidelity = fidelity;
        p.tile = settings.tile;
        p.bytes_per_ray = ray_record_bytes(shape.features);
        p.timing = fidelity == Fidelity::analytic ? analytic_timing(configs[i], shape, profile)
                                                  : systemc->timing(i);
        for (int sec = 0; sec < 2; ++sec)
            for (uint32_t k = 0; k < k_op_stage_count; ++k)
                p.ideal_utilization[sec][k] = counts.stage(sec, OpStage(k)).utilization(i, widths[i]);
        for (uint32_t k = 0; k < k_op_stage_count; ++k) {
            // Over all rays: lanes over issued lane slots, from both halves.
            const auto& a = counts.stage(false, OpStage(k));
            const auto& b = counts.stage(true, OpStage(k));
            const double slots = double(widths[i]) * double(a.groups[i] + b.groups[i]);
            p.ideal_utilization_all[k] = slots > 0 ? double(a.lanes + b.lanes) / slots : 0.0;
        }
        p.total_passes = p.sample_passes = counts.passes();
        // The functional render and the shared simulation are split evenly over the group.
        p.host_seconds = shared_seconds / double(configs.size()) + seconds_since(model_start);
        result.predictions.push_back(std::move(p));
    }
    result.host_seconds = seconds_since(start);
    return result;
}

}  // namespace sfx
