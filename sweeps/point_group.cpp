#include "sweeps/point_group.h"

#include <algorithm>
#include <cmath>
#include <memory>
#include <mutex>
#include <thread>

#include "hw_model/analytic_model.h"
#include "hw_model/pass_buffer.h"
#include "hw_model/systemc/systemc_timing.h"
#include "kernels/stream/stream_tracer.h"
#include "base/host_clock.h"
#include "base/input_error.h"
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

// Forwards to a timing model and adds up the seconds spent in its pass and frame calls (where
// it simulates), so the host time splits into render and timing. Ops are not timed (a clock
// read per op would cost more than the op's copy): their recording counts as render time.
class TimedSink : public TraceSink {
public:
    explicit TimedSink(TraceSink& inner) : m_inner(inner) {}
    void begin_frame(const TraceHeader& h) override { timed([&] { m_inner.begin_frame(h); }); }
    void begin_pass(const TilePass& p) override { timed([&] { m_inner.begin_pass(p); }); }
    void op(const StreamOp& o) override { m_inner.op(o); }
    void end_pass(const TilePass& p) override { timed([&] { m_inner.end_pass(p); }); }
    void end_frame() override { timed([&] { m_inner.end_frame(); }); }
    double seconds() const { return m_seconds; }

private:
    template <class F>
    void timed(F&& f) {
        const auto start = HostClock::now();
        f();
        m_seconds += seconds_since(start);
    }
    TraceSink& m_inner;
    double m_seconds = 0.0;
};



// Ideal utilization at configuration i's width from the counted trace.
void fill_ideal(Prediction& p, const CountingSink& counts, size_t i, uint32_t width) {
    for (int sec = 0; sec < 2; ++sec)
        for (uint32_t k = 0; k < k_op_stage_count; ++k)
            p.ideal_utilization[sec][k] = counts.stage(sec, OpStage(k)).utilization(i, width);
    for (uint32_t k = 0; k < k_op_stage_count; ++k) {
        const auto& a = counts.stage(false, OpStage(k));
        const auto& b = counts.stage(true, OpStage(k));
        const double slots = double(width) * double(a.groups[i] + b.groups[i]);
        p.ideal_utilization_all[k] = slots > 0 ? double(a.lanes + b.lanes) / slots : 0.0;
    }
}

// What the workload did, whatever the hardware: box tests per traced ray (primary, secondary),
// the primary entry points' mean depth, rays per node per bounce, RayGrid's queues.
void fill_workload(Prediction& p, const CountingSink& counts, const RenderStats& render) {
    for (int sec = 0; sec < 2; ++sec) {
        const uint64_t rays = counts.rays(sec);
        p.box_tests_per_ray[sec] =
            rays ? double(counts.kind_lanes(OpKind::box_test, sec)) / double(rays) : 0.0;
    }
    p.entry_depth = render.entry_searches
                        ? double(render.entry_depth_sum) / double(render.entry_searches)
                        : 0.0;
    for (uint32_t g = 0; g < Prediction::k_bounces; ++g) {
        const CountingSink::BounceCounts& b = counts.bounce(g);
        p.rays_per_node[g] = b.rays_per_node();
        p.rays_per_leaf[g] = b.rays_per_leaf();
        p.bounce_box_tests_per_ray[g] = b.box_tests_per_ray();
    }
    if (const uint64_t rays = counts.rays(true))
        p.batch_lanes_per_ray = double(counts.kind_lanes(OpKind::raygrid_walk) +
                                       counts.kind_lanes(OpKind::raygrid_enqueue)) /
                                double(rays);
    if (render.batch_queues) {
        p.batch_mean_queue = double(render.batch_queued_rays) / double(render.batch_queues);
        p.batch_full_share = double(render.batch_full_queues) / double(render.batch_queues);
    }
}

// Counts finished passes for a PassProgress (the trace arrives in order, one pass at a time).
class ProgressSink : public TraceSink {
public:
    ProgressSink(const PassProgress& progress, uint64_t total)
        : m_progress(progress), m_total(total) {}
    void op(const StreamOp&) override {}
    void end_pass(const TilePass&) override { m_progress(++m_done, m_total); }

private:
    const PassProgress& m_progress;
    uint64_t m_total, m_done = 0;
};

// Sums the lanes of a pass: the pilot's cost estimate of a tile.
class LaneCounter : public TraceSink {
public:
    void op(const StreamOp& op) override { lanes += op.length; }
    uint64_t lanes = 0;
};

// Holds the passes of one traced unit: warm-up passes first, the sampled pass last.
class UnitPasses : public TraceSink {
public:
    void begin_pass(const TilePass& p) override { passes.emplace_back(); passes.back().begin_pass(p); }
    void op(const StreamOp& o) override { passes.back().op(o); }
    void end_pass(const TilePass& p) override { passes.back().end_pass(p); }
    std::vector<PassBuffer> passes;
};

void replay(const PassBuffer& b, TraceSink& sink) {
    sink.begin_pass(b.pass());
    for (size_t i = 0; i < b.size(); ++i) sink.op(b.at(i));
    sink.end_pass(b.pass());
}


// Calibrates the analytic model against the cycle-level one on the same frame: every k-th
// tile pass (a systematic sample across the image, k = 1 / fraction) is also timed at cycle
// level, after its predecessor has warmed the caches, and priced by the analytic model alone.
// The ratio of the two over the sample scales each configuration's analytic frame, and the
// ratio's interval is the calibrated prediction's error estimate.
class AnalyticCalibration : public TraceSink {
public:
    AnalyticCalibration(const std::vector<HwConfig>& configs, const WorkloadShape& shape,
                        uint32_t stride)
        : m_configs(configs), m_shape(shape), m_stride(std::max(1u, stride)),
          m_timing(configs, shape), m_cycle(configs.size()) {}

    void begin_pass(const TilePass& p) override {
        m_current.begin_pass(p);
        m_selected = m_unit % m_stride == m_stride / 2;
    }
    void op(const StreamOp& o) override { m_current.op(o); }
    void end_pass(const TilePass& p) override {
        m_current.end_pass(p);
        if (m_selected) {
            if (m_unit > 0) {
                m_timing.set_warming(true);
                replay(m_previous, m_timing);
                m_timing.set_warming(false);
            }
            std::vector<FrameTiming> before;
            for (size_t c = 0; c < m_configs.size(); ++c) before.push_back(m_timing.timing(c));
            replay(m_current, m_timing);
            m_profiles.emplace_back(m_shape);
            replay(m_current, m_profiles.back());
            for (size_t c = 0; c < m_configs.size(); ++c)
                m_cycle[c].push_back(double(timing_between(before[c], m_timing.timing(c)).cycles));
        }
        std::swap(m_previous, m_current);
        ++m_unit;
    }

    // Ratio cycle-level / analytic for configuration c, and the relative half-width of its
    // interval (ratio estimator, finite-population corrected); {1, -1} without a sample. Each
    // sampled pass is priced with the whole frame's working sets (`frame`), as the frame is.
    std::pair<double, double> ratio(size_t c, double confidence, const TraceProfile& frame) const {
        const std::vector<double>& y = m_cycle[c];
        std::vector<double> x;
        for (const TraceProfile& one : m_profiles)
            x.push_back(double(analytic_timing(m_configs[c], m_shape, one, &frame).cycles));
        const size_t n = y.size();
        double sy = 0, sx = 0;
        for (size_t i = 0; i < n; ++i) { sy += y[i]; sx += x[i]; }
        if (n < 1 || sx <= 0.0) return {1.0, -1.0};
        const double r = sy / sx, mean_x = sx / double(n);
        // Every pass of the frame timed: the ratio is the frame's own (no sampling error).
        if (n >= m_unit) return {r, 0.0};
        if (n < 2) return {1.0, -1.0};
        double s2 = 0.0;
        for (size_t i = 0; i < n; ++i) s2 += (y[i] - r * x[i]) * (y[i] - r * x[i]);
        s2 /= double(n - 1);
        const double f = double(n) / double(std::max<uint64_t>(n, m_unit));
        // Student's t with n - 1 degrees of freedom: the calibration sample may be small.
        const double half = student_t_quantile_two_sided(confidence, double(n - 1)) *
                            std::sqrt((1.0 - f) * s2 / double(n)) / mean_x;
        return {r, half / r};
    }
    uint64_t sampled() const { return m_cycle.empty() ? 0 : m_cycle[0].size(); }

private:
    const std::vector<HwConfig>& m_configs;
    WorkloadShape m_shape;
    uint32_t m_stride;
    SystemcTiming m_timing;
    PassBuffer m_current, m_previous;
    bool m_selected = false;
    uint64_t m_unit = 0;
    std::vector<std::vector<double>> m_cycle;
    std::vector<TraceProfile> m_profiles;  // of the sampled passes
};

// Configurations of a group calibrated at cycle level: all of a small group, else a systematic
// sample across it (a sweep's last axis moves fastest, so every axis is spanned).
constexpr size_t k_calibrated_configs = 8;
std::vector<size_t> calibration_subset(size_t configs) {
    std::vector<size_t> out;
    const size_t n = std::min(configs, k_calibrated_configs);
    for (size_t k = 0; k < n; ++k) out.push_back(k * configs / n + configs / (2 * n));
    out.erase(std::unique(out.begin(), out.end()), out.end());
    return out;
}

// Every k-th tile pass is calibrated, k = 1 / fraction, but at least k_calibration_passes of
// the frame's (all of a frame with fewer): a small frame still gets an interval.
constexpr uint64_t k_calibration_passes = 4;
uint32_t calibration_stride(double fraction, uint64_t frame_passes) {
    const uint64_t wanted = uint64_t(std::max(1L, std::lround(1.0 / fraction)));
    return uint32_t(std::max<uint64_t>(1, std::min(wanted, frame_passes / k_calibration_passes)));
}

}  // namespace

std::vector<std::vector<std::string>> varying_parameters(const std::vector<HwConfig>& configs) {
    std::vector<std::vector<HwParamInfo>> flat;
    for (const HwConfig& c : configs) flat.push_back(flatten_hw_config(c));
    std::vector<size_t> varying;  // parameter indices whose values differ in the group
    for (size_t p = 0; !flat.empty() && p < flat[0].size(); ++p) {
        if (flat[0][p].path == "name") continue;
        for (const auto& f : flat)
            if (f.size() != flat[0].size() || f[p].value != flat[0][p].value) {
                varying.push_back(p);
                break;
            }
    }
    std::vector<std::vector<std::string>> out(configs.size());
    for (size_t i = 0; i < configs.size(); ++i)
        for (size_t p : varying)
            // A configuration with another cache hierarchy lists other parameters: its own value.
            out[i].push_back(p < flat[i].size() && flat[i].size() == flat[0].size()
                                 ? flat[i][p].value
                                 : "#" + std::to_string(i));
    return out;
}

std::vector<std::pair<double, double>> uncalibrated_ratios(
    const std::vector<std::vector<std::string>>& knobs, const std::vector<size_t>& calibrated,
    const std::vector<double>& r, const std::vector<double>& half, double confidence) {
    const size_t n = r.size(), configs = knobs.size();
    std::vector<std::pair<double, double>> out(configs, {1.0, -1.0});
    std::vector<uint8_t> is_calibrated(configs, 0);
    for (size_t c : calibrated) is_calibrated[c] = 1;
    if (n == 0 || std::any_of(half.begin(), half.end(), [](double h) { return h < 0.0; }))
        return out;  // a calibration without an interval says nothing of the others
    double mean = 0, mean_half = 0;
    for (size_t k = 0; k < n; ++k) {
        mean += r[k] / double(n);
        mean_half += half[k] / double(n);
    }
    if (n < 2 || mean <= 0.0) {
        for (size_t i = 0; i < configs; ++i)
            if (!is_calibrated[i]) out[i] = {mean > 0.0 ? mean : 1.0, 2.0 * mean_half};
        return out;
    }
    const double t = student_t_quantile_two_sided(confidence, double(n - 1));
    // The mean of the calibrated ratios sharing configuration i's value of parameter `p`
    // (every calibrated one when p is none), leaving out calibrated number `skip`; false if
    // none is left.
    const size_t none = knobs.empty() ? 0 : knobs[0].size();
    auto stratum_mean = [&](size_t i, size_t p, size_t skip, double& ratio, double& h) {
        double sum = 0, sum_half = 0;
        size_t count = 0;
        for (size_t k = 0; k < n; ++k) {
            if (k == skip || (p < none && knobs[calibrated[k]][p] != knobs[i][p])) continue;
            sum += r[k];
            sum_half += half[k];
            ++count;
        }
        if (count == 0) return false;
        ratio = sum / double(count);
        h = sum_half / double(count);
        return true;
    };
    // Leave-one-out: the mean squared relative error of rule p (none: the sample's mean) when
    // each calibrated configuration is predicted from the others.
    auto left_out_error = [&](size_t p) {
        double sq = 0.0;
        for (size_t k = 0; k < n; ++k) {
            double predicted = 0, h = 0;
            if (!stratum_mean(calibrated[k], p, k, predicted, h))
                stratum_mean(calibrated[k], none, k, predicted, h);
            sq += (predicted / r[k] - 1.0) * (predicted / r[k] - 1.0) / double(n);
        }
        return sq;
    };
    size_t best = none;
    double best_sq = left_out_error(none);
    for (size_t p = 0; p < none; ++p) {
        const double sq = left_out_error(p);
        if (sq < best_sq) {
            best = p;
            best_sq = sq;
        }
    }
    double s2 = 0;
    for (double x : r) s2 += (x - mean) * (x - mean) / double(n - 1);
    const double mean_spread = t * std::sqrt(s2 * (1.0 + 1.0 / double(n))) / mean;
    const double stratum_spread = t * std::sqrt(best_sq);
    for (size_t i = 0; i < configs; ++i) {
        if (is_calibrated[i]) continue;
        double ratio = 0, h = 0;
        if (best != none && stratum_mean(i, best, n, ratio, h))
            out[i] = {ratio, std::sqrt(stratum_spread * stratum_spread + h * h)};
        else
            out[i] = {mean, std::sqrt(mean_spread * mean_spread + mean_half * mean_half)};
    }
    return out;
}

namespace {

PointGroupResult run_sampled(const Scene& scene, const Bvh& bvh, const RenderSettings& settings,
                             const std::vector<HwConfig>& configs, const SamplingOptions& opt,
                             const PassProgress& progress) {
    const auto start = HostClock::now();
    const WorkloadShape shape = workload_shape(scene, bvh, settings);
    check_tile_fits(settings.tile, shape.features, configs, "--tile");
    if (!(opt.fraction > 0.0 && opt.fraction <= 1.0))
        throw InputError("command line", 0, "--sample-fraction", "must lie in (0, 1]");
    if (opt.target_error < 0.0)
        throw InputError("command line", 0, "--target-error", "must be positive");
    const std::vector<TileRect> tiles = make_tiles(settings.width, settings.height, settings.tile);
    const uint32_t spp = settings.spp;
    const uint32_t units = uint32_t(tiles.size()) * spp;
    const uint32_t slots = settings.tile * settings.tile;
    const uint32_t threads =
        settings.threads ? settings.threads : std::max(1u, std::thread::hardware_concurrency());
    std::vector<std::unique_ptr<StreamTracer>> tracers(threads);
    std::vector<std::vector<Vec3>> sums(threads, std::vector<Vec3>(slots));
    std::vector<RenderStats> stats(threads);
    // parallel_for hands out indices to any thread; a tracer per worker slot, claimed by id.
    std::mutex claim_mutex;
    std::vector<bool> busy(threads, false);
    auto with_tracer = [&](auto&& body) {
        size_t slot;
        {
            std::lock_guard<std::mutex> lock(claim_mutex);
            slot = size_t(std::find(busy.begin(), busy.end(), false) - busy.begin());
            busy[slot] = true;
        }
        if (!tracers[slot]) tracers[slot] = std::make_unique<StreamTracer>(scene, bvh, settings);
        body(*tracers[slot], sums[slot].data(), stats[slot]);
        std::lock_guard<std::mutex> lock(claim_mutex);
        busy[slot] = false;
    };

    // Strata: by a pilot estimate of each tile's cost (its sample-0 pass, traced functionally)
    // when spp is high enough for the pilot to be cheap, else by image region.
    Stratification strata;
    if (spp >= opt.pilot_min_spp) {
        std::vector<double> cost(tiles.size());
        parallel_for(uint32_t(tiles.size()), threads, [&](uint32_t t) {
            with_tracer([&](StreamTracer& tracer, Vec3* s, RenderStats& st) {
                LaneCounter lanes;
                tracer.trace_pass(tiles[t], t, 0, s, st, &lanes);
                cost[t] = double(lanes.lanes);
            });
        });
        strata = stratify_tiles_by_cost(cost, spp, opt.strata);
    } else {
        strata = stratify_tiles_by_region(uint32_t(tiles.size()), spp, opt.strata);
    }
    StratifiedSampler sampler(strata, opt.seed ^ settings.seed);

    std::vector<uint32_t> widths;
    for (const HwConfig& c : configs) widths.push_back(c.simd.width);
    CountingSink counts(widths);
    SystemcTiming timing(configs, shape);
    std::vector<uint32_t> sampled;                       // units, in the order timed
    std::vector<std::vector<FrameTiming>> per_unit(configs.size());
    std::vector<Estimate> estimates(configs.size());
    uint64_t target = std::max<uint64_t>(2ull * strata.strata, uint64_t(std::ceil(opt.fraction * units)));
    const uint32_t chunk = 4 * threads;
    for (;;) {
        const std::vector<uint32_t> batch = sampler.grow_to(target);
        for (size_t first = 0; first < batch.size(); first += chunk) {
            const size_t count = std::min<size_t>(chunk, batch.size() - first);
            std::vector<UnitPasses> traced(count);
            parallel_for(uint32_t(count), threads, [&](uint32_t i) {
                const uint32_t unit = batch[first + i];
                with_tracer([&](StreamTracer& tracer, Vec3* s, RenderStats& st) {
                    // The passes that precede this one in execution order warm the caches.
                    const uint32_t warm = std::min<uint32_t>(opt.warmup_passes, unit);
                    for (uint32_t u = unit - warm; u <= unit; ++u)
                        tracer.trace_pass(tiles[u / spp], u / spp, u % spp, s, st, &traced[i]);
                });
            });
            for (size_t i = 0; i < count; ++i) {
                const std::vector<PassBuffer>& passes = traced[i].passes;
                timing.set_warming(true);
                for (size_t w = 0; w + 1 < passes.size(); ++w) replay(passes[w], timing);
                timing.set_warming(false);
                std::vector<FrameTiming> before(configs.size());
                for (size_t c = 0; c < configs.size(); ++c) before[c] = timing.timing(c);
                replay(passes.back(), timing);
                replay(passes.back(), counts);
                for (size_t c = 0; c < configs.size(); ++c)
                    per_unit[c].push_back(timing_between(before[c], timing.timing(c)));
                sampled.push_back(batch[first + i]);
            }
            if (progress) progress(sampled.size(), std::max<uint64_t>(target, sampled.size()));
        }
        double worst = 0.0;
        for (size_t c = 0; c < configs.size(); ++c) {
            std::vector<double> cycles;
            for (const FrameTiming& t : per_unit[c]) cycles.push_back(double(t.cycles));
            estimates[c] = estimate_total(strata, sampled, cycles, opt.confidence);
            worst = std::max(worst, estimates[c].relative());
        }
        if (opt.target_error <= 0.0 || worst <= opt.target_error || sampled.size() >= units) break;
        target = std::min<uint64_t>(units, std::max<uint64_t>(target + 1, uint64_t(target * 1.5)));
    }

    // Expand each sampled pass to its stratum: weight N_h / n_h.
    const std::vector<uint64_t> sizes = strata.sizes();
    std::vector<uint64_t> taken(strata.strata, 0);
    for (uint32_t u : sampled) ++taken[strata.stratum_of[u]];
    PointGroupResult result;
    const double seconds = seconds_since(start);
    for (size_t c = 0; c < configs.size(); ++c) {
        Prediction p;
        p.config = configs[c];
        p.fidelity = Fidelity::sampled;
        p.tile = settings.tile;
        p.bytes_per_ray = ray_record_bytes(shape.features);
        for (size_t i = 0; i < sampled.size(); ++i) {
            const uint32_t h = strata.stratum_of[sampled[i]];
            p.timing.add_scaled(per_unit[c][i], double(sizes[h]) / double(taken[h]));
        }
        p.timing.cycles = uint64_t(std::llround(estimates[c].total));  // the estimator's own
        fill_ideal(p, counts, c, widths[c]);
        p.error_relative = estimates[c].relative();
        p.sample_passes = sampled.size();
        p.total_passes = units;
        p.host_seconds = seconds / double(configs.size());
        result.predictions.push_back(std::move(p));
    }
    for (const RenderStats& st : stats) result.render += st;
    for (Prediction& p : result.predictions) fill_workload(p, counts, result.render);
    result.host_seconds = seconds_since(start);
    return result;
}

}  // namespace

std::vector<uint8_t> bvh_leaves(const Bvh& bvh) {
    std::vector<uint8_t> leaf(bvh.nodes().size());
    for (size_t i = 0; i < leaf.size(); ++i) leaf[i] = bvh.nodes()[i].is_leaf();
    return leaf;
}

WorkloadShape workload_shape(const Scene& scene, const Bvh& bvh, const RenderSettings& settings) {
    WorkloadShape shape;
    shape.features = scene.features();
    shape.features.max_depth = settings.max_depth;
    shape.triangles = scene.triangles.size();
    shape.spheres = scene.spheres.size();
    shape.bvh_nodes = bvh.nodes().size();
    shape.vertices = scene.positions.size();
    shape.node_leaf = std::make_shared<const std::vector<uint8_t>>(bvh_leaves(bvh));
    shape.tile = settings.tile;
    shape.primary_entry_aepsa = settings.primary_entry == PrimaryEntry::aepsa;
    shape.reorder_hit_point = settings.reorder == RayReorder::hit_point;
    shape.batching_raygrid = settings.batching == RayBatching::raygrid;
    return shape;
}

PointGroupResult run_point_group(const Scene& scene, const Bvh& bvh, const RenderSettings& settings,
                                 const std::vector<HwConfig>& configs, Fidelity fidelity,
                                 const SamplingOptions& sampling, const PassProgress& progress) {
    for (const HwConfig& c : configs) check_machine_model_config(c);
    if (fidelity == Fidelity::sampled)
        return run_sampled(scene, bvh, settings, configs, sampling, progress);
    const auto start = HostClock::now();
    const WorkloadShape shape = workload_shape(scene, bvh, settings);
    check_tile_fits(settings.tile, shape.features, configs, "--tile");

    std::vector<uint32_t> widths;
    for (const HwConfig& c : configs) widths.push_back(c.simd.width);
    CountingSink counts(widths);
    FanOutSink fan;
    fan.add(&counts);
    TraceProfile profile(shape);
    std::unique_ptr<SystemcTiming> systemc;
    std::unique_ptr<TimedSink> timed_systemc;
    std::unique_ptr<AnalyticCalibration> calibration;
    const uint64_t frame_passes =
        uint64_t(make_tiles(settings.width, settings.height, settings.tile).size()) * settings.spp;
    // SMARTS-style: the cycle-level calibration runs on a systematic sample of the group's
    // configurations; the others take a ratio and an interval from it (uncalibrated_ratios).
    const std::vector<size_t> calibrated = calibration_subset(configs.size());
    std::vector<HwConfig> calibrated_configs;
    for (size_t c : calibrated) calibrated_configs.push_back(configs[c]);
    if (fidelity == Fidelity::analytic) {
        fan.add(&profile);
        if (sampling.calibration_fraction > 0.0) {
            calibration = std::make_unique<AnalyticCalibration>(
                calibrated_configs, shape, calibration_stride(sampling.calibration_fraction, frame_passes));
            fan.add(calibration.get());
        }
    } else {
        systemc = std::make_unique<SystemcTiming>(configs, shape);
        timed_systemc = std::make_unique<TimedSink>(*systemc);
        fan.add(timed_systemc.get());
    }
    std::unique_ptr<ProgressSink> progress_sink;  // last: counts a pass once it is timed
    if (progress) {
        progress_sink = std::make_unique<ProgressSink>(progress, frame_passes);
        fan.add(progress_sink.get());
    }
    PointGroupResult result;
    // Warm frames: the workload's other frames (other_frame: another seed each, as a
    // progressive renderer's frames before this one; the last is other_frame 1) into the caches
    // only; the timed frame's counters exclude their lookups. Where others fill a cache level
    // (foreign_fill_per_us), lines are lost by age: the warm frames are then timed too, so that
    // each line is as old when the timed frame starts as the render before left it (untimed,
    // every line would be fresh).
    std::vector<FrameTiming> warmed(configs.size());
    if (systemc && sampling.warm_frames > 0) {
        const bool by_age = std::any_of(configs.begin(), configs.end(), [](const HwConfig& c) {
            return std::any_of(c.scene_memory.caches.begin(), c.scene_memory.caches.end(),
                               [](const CacheLevelConfig& l) { return l.foreign_fill_per_us > 0; });
        });
        systemc->set_warming(!by_age);
        for (uint32_t f = 0; f < sampling.warm_frames; ++f)
            render_stream(scene, bvh, other_frame(settings, sampling.warm_frames - f),
                          systemc.get());
        systemc->set_warming(false);
        for (size_t c = 0; c < configs.size(); ++c) warmed[c] = systemc->timing(c);
    }
    result.render = render_stream(scene, bvh, settings, &fan).stats;
    const double shared_seconds = seconds_since(start);
    result.timing_seconds = timed_systemc ? timed_systemc->seconds() : 0.0;

    // Calibration ratios (cycle level / analytic) and their intervals, per calibrated
    // configuration; the rest of the group is priced from their spread.
    std::vector<std::pair<double, double>> ratios(configs.size(), {1.0, -1.0});
    if (calibration && calibration->sampled() >= 1) {
        std::vector<double> r, half;
        for (size_t k = 0; k < calibrated.size(); ++k) {
            const std::pair<double, double> own = calibration->ratio(k, sampling.confidence, profile);
            r.push_back(own.first);
            half.push_back(own.second);
        }
        ratios = uncalibrated_ratios(varying_parameters(configs), calibrated, r, half,
                                     sampling.confidence);
        for (size_t k = 0; k < calibrated.size(); ++k) ratios[calibrated[k]] = {r[k], half[k]};
    }

    for (size_t i = 0; i < configs.size(); ++i) {
        const auto model_start = HostClock::now();
        Prediction p;
        p.config = configs[i];
        p.fidelity = fidelity;
        p.tile = settings.tile;
        p.bytes_per_ray = ray_record_bytes(shape.features);
        p.timing = fidelity == Fidelity::analytic ? analytic_timing(configs[i], shape, profile)
                  : sampling.warm_frames > 0 ? timing_between(warmed[i], systemc->timing(i))
                                             : systemc->timing(i);
        fill_ideal(p, counts, i, widths[i]);
        // Passes timed at cycle level: all of them at full fidelity; at analytic fidelity only
        // the calibration sample, if any.
        p.total_passes = counts.passes();
        p.sample_passes = fidelity == Fidelity::full ? counts.passes() : 0;
        if (ratios[i].second >= 0.0) {
            p.timing.cycles = uint64_t(std::llround(double(p.timing.cycles) * ratios[i].first));
            p.error_relative = ratios[i].second;
            if (std::binary_search(calibrated.begin(), calibrated.end(), i))
                p.sample_passes = calibration->sampled();
        }
        // The closed form's causes, in proportion, fill the cycles its work leaves.
        if (fidelity == Fidelity::analytic) fit_stalls_to_cycles(p.timing, configs[i].simd.units);
        // Full fidelity is the reference the other levels are measured against: no sampling
        // error. An uncalibrated analytic point's error is unknown (-1).
        if (fidelity == Fidelity::full) p.error_relative = 0.0;
        fill_workload(p, counts, result.render);
        // The functional render and the shared simulation are split evenly over the group.
        p.host_seconds = shared_seconds / double(configs.size()) + seconds_since(model_start);
        result.predictions.push_back(std::move(p));
    }
    result.host_seconds = seconds_since(start);
    return result;
}

}  // namespace sfx
