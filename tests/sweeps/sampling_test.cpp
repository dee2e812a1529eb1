// Sampled fidelity: the interval covers the truth, shrinks with the sample, and adaptive
// sampling stops at its target.

#include <catch2/catch.hpp>
#include <cmath>

#include "hw_model/systemc/systemc_timing.h"
#include "kernels/bvh.h"
#include "kernels/stream/stream_tracer.h"
#include "sweeps/point_group.h"
#include "sweeps/sampling.h"
#include "workloads/scene_loader.h"

using namespace sfx;

namespace {

// Cycles of every tile pass of a frame, in execution order, from the cycle-level model.
class PassCycles : public TraceSink {
public:
    explicit PassCycles(SystemcTiming& timing) : m_timing(timing) {}
    void begin_pass(const TilePass& p) override { m_timing.begin_pass(p); }
    void op(const StreamOp& o) override { m_timing.op(o); }
    void end_pass(const TilePass& p) override {
        m_timing.end_pass(p);
        const uint64_t now = m_timing.timing(0).cycles;
        cycles.push_back(double(now - m_last));
        m_last = now;
    }
    std::vector<double> cycles;

private:
    SystemcTiming& m_timing;
    uint64_t m_last = 0;
};

RenderSettings small_settings(const Scene& scene) {
    RenderSettings s;
    s.width = s.height = 64;
    s.spp = 8;
    s.tile = 8;
    s.max_depth = scene.max_depth;
    s.threads = 2;
    return s;
}

// A frame of 32x32 pixels, one sample each, in tiles of 16: the warm-frame tests' workload.
RenderSettings warm_frame_settings(const Scene& scene) {
    RenderSettings s = small_settings(scene);
    s.width = s.height = 32;
    s.spp = 1;
    s.tile = 16;
    return s;
}

// Every width x units x banks (the rest gr08's), last fastest; named by width.
std::vector<HwConfig> width_unit_bank_grid(std::initializer_list<uint32_t> widths,
                                           std::initializer_list<uint32_t> units,
                                           std::initializer_list<uint32_t> banks) {
    std::vector<HwConfig> configs;
    for (uint32_t w : widths)
        for (uint32_t u : units)
            for (uint32_t b : banks) {
                HwConfig c;
                c.simd.width = w;
                c.simd.units = u;
                c.ray_buffer.banks = b;
                c.name = "w" + std::to_string(w);
                configs.push_back(c);
            }
    return configs;
}

}  // namespace

TEST_CASE("Normal and Student t quantiles", "[sampling]") {
    CHECK(normal_quantile_two_sided(0.95) == Approx(1.959964).epsilon(1e-5));
    CHECK(normal_quantile_two_sided(0.997) == Approx(2.967738).epsilon(1e-5));
    // Tables: t(0.975; 1) = 12.7062, t(0.975; 10) = 2.2281; large df tends to z.
    CHECK(student_t_quantile_two_sided(0.95, 1) == Approx(12.7062).epsilon(1e-5));
    CHECK(student_t_quantile_two_sided(0.95, 10) == Approx(2.2281).epsilon(1e-4));
    CHECK(student_t_quantile_two_sided(0.997, 1e7) == Approx(2.967738).epsilon(1e-5));
    CHECK_THROWS(student_t_quantile_two_sided(0.95, 0));
    CHECK_THROWS(normal_quantile_two_sided(1.0));
}

TEST_CASE("Stratified estimate: Satterthwaite degrees of freedom", "[sampling]") {
    // Two strata of 10 units, 2 sampled each: a_h = N^2 (1 - n/N) / n = 40 for both.
    Stratification strata;
    strata.strata = 2;
    strata.stratum_of = {0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 1, 1, 1, 1, 1, 1, 1, 1, 1, 1};
    // Equal variances (s^2 = 2 in both): df = (2 v)^2 / (2 v^2 / 1) = 2, the pooled n - strata.
    const Estimate equal = estimate_total(strata, {0, 1, 10, 11}, {1, 3, 5, 7}, 0.95);
    CHECK(equal.degrees_of_freedom == Approx(2.0));
    CHECK(equal.total == Approx(10 * 2 + 10 * 6));
    CHECK(equal.half_width == Approx(student_t_quantile_two_sided(0.95, 2) * std::sqrt(160.0)));
    // One stratum carries all the variance: df is that stratum's n - 1 = 1.
    const Estimate one = estimate_total(strata, {0, 1, 10, 11}, {1, 3, 5, 5}, 0.95);
    CHECK(one.degrees_of_freedom == Approx(1.0));
    // No variance at all: no interval.
    const Estimate none = estimate_total(strata, {0, 1, 10, 11}, {4, 4, 5, 5}, 0.95);
    CHECK(none.half_width == 0.0);
}

TEST_CASE("Stratified sampling: the 99.7% interval covers the full-fidelity total in >= 97 of "
          "100 seeded repetitions and shrinks as the sample grows",
          "[sampling]") {
    const Scene scene = load_scene("cornell");
    const Bvh bvh(scene);
    const RenderSettings settings = small_settings(scene);
    const WorkloadShape shape = workload_shape(scene, bvh, settings);
    SystemcTiming timing({HwConfig{}}, shape);
    PassCycles passes(timing);
    render_stream(scene, bvh, settings, &passes);
    // The population: the cycle-level model's cycles of each pass (a cheap timing model to
    // sample from many times).
    const std::vector<double>& population = passes.cycles;
    const uint32_t tiles = 64;
    REQUIRE(population.size() == tiles * settings.spp);
    double truth = 0.0;
    for (double c : population) truth += c;
    // Tile cost for the strata: the sample-0 pass of each tile (the pilot).
    std::vector<double> pilot(tiles);
    for (uint32_t t = 0; t < tiles; ++t) pilot[t] = population[t * settings.spp];
    const Stratification strata = stratify_tiles_by_cost(pilot, settings.spp, 4);

    auto mean_half_width = [&](double fraction, int& covered) {
        double sum = 0.0;
        covered = 0;
        for (uint64_t seed = 1; seed <= 100; ++seed) {
            StratifiedSampler sampler(strata, seed);
            const std::vector<uint32_t> units =
                sampler.grow_to(uint64_t(std::ceil(fraction * double(population.size()))));
            std::vector<double> values;
            for (uint32_t u : units) values.push_back(population[u]);
            const Estimate e = estimate_total(strata, units, values, 0.997);
            covered += std::fabs(e.total - truth) <= e.half_width;
            sum += e.relative();
        }
        return sum / 100.0;
    };
    int covered_two = 0, covered_small = 0, covered_mid = 0, covered_large = 0;
    // Two passes per stratum (8 of 512): where a normal z interval is far too narrow.
    const double two = mean_half_width(8.0 / double(population.size()), covered_two);
    const double small = mean_half_width(0.05, covered_small);
    const double mid = mean_half_width(0.2, covered_mid);
    const double large = mean_half_width(0.5, covered_large);
    INFO("coverage " << covered_two << " " << covered_small << " " << covered_mid << " "
                     << covered_large << "; half-widths " << two << " " << small << " " << mid
                     << " " << large);
    CHECK(covered_two >= 97);
    CHECK(two > small);
    CHECK(covered_small >= 97);
    CHECK(covered_mid >= 97);
    CHECK(covered_large >= 97);
    CHECK(small > mid);
    CHECK(mid > large);
    // The whole population: no sampling error.
    StratifiedSampler all(strata, 1);
    const std::vector<uint32_t> units = all.grow_to(population.size());
    std::vector<double> values;
    for (uint32_t u : units) values.push_back(population[u]);
    const Estimate e = estimate_total(strata, units, values, 0.997);
    CHECK(e.half_width == 0.0);
    CHECK(e.total == Approx(truth));
}

TEST_CASE("Sampled fidelity agrees with full within its interval, adaptive sampling stops at "
          "its target",
          "[sampling]") {
    const Scene scene = load_scene("cornell");
    const Bvh bvh(scene);
    const RenderSettings settings = small_settings(scene);
    const std::vector<HwConfig> configs = {HwConfig{}};
    const Prediction full = run_point_group(scene, bvh, settings, configs, Fidelity::full).predictions[0];
    SamplingOptions options;
    options.fraction = 0.25;
    const Prediction sampled =
        run_point_group(scene, bvh, settings, configs, Fidelity::sampled, options).predictions[0];
    CHECK(sampled.sample_passes < sampled.total_passes);
    CHECK(sampled.total_passes == full.total_passes);
    const double error = std::fabs(double(sampled.timing.cycles) / double(full.timing.cycles) - 1.0);
    INFO("sampled error " << error << " interval " << sampled.error_relative);
    // Warm-up leaves a small bias of its own on top of the sampling error.
    CHECK(error <= sampled.error_relative + 0.02);

    for (double target : {0.05, 0.02}) {
        SamplingOptions adaptive;
        adaptive.fraction = 0.02;
        adaptive.target_error = target;
        const Prediction p =
            run_point_group(scene, bvh, settings, configs, Fidelity::sampled, adaptive).predictions[0];
        INFO("target " << target << " reached " << p.error_relative << " with " << p.sample_passes
                       << " of " << p.total_passes);
        CHECK((p.error_relative <= target || p.sample_passes == p.total_passes));
        CHECK(p.sample_passes > uint64_t(0.02 * p.total_passes));  // it had to grow
    }
}

TEST_CASE("Calibrated analytic fidelity: within its interval of full, uncalibrated says unknown",
          "[sampling]") {
    const Scene scene = load_scene("cornell");
    const Bvh bvh(scene);
    const RenderSettings settings = small_settings(scene);
    HwConfig w8;
    w8.simd.width = 8;
    const std::vector<HwConfig> configs = {HwConfig{}, w8};
    const PointGroupResult full = run_point_group(scene, bvh, settings, configs, Fidelity::full);
    SamplingOptions calibrated;
    calibrated.calibration_fraction = 0.05;
    const PointGroupResult analytic =
        run_point_group(scene, bvh, settings, configs, Fidelity::analytic, calibrated);
    for (size_t c = 0; c < configs.size(); ++c) {
        const Prediction& a = analytic.predictions[c];
        const double error = std::fabs(double(a.timing.cycles) / double(full.predictions[c].timing.cycles) - 1.0);
        INFO("config " << c << " calibrated analytic error " << error << " interval " << a.error_relative);
        CHECK(a.error_relative >= 0.0);
        CHECK(a.sample_passes >= 2);
        CHECK(error <= a.error_relative + 0.02);
    }
    SamplingOptions none;
    none.calibration_fraction = 0.0;
    const Prediction raw =
        run_point_group(scene, bvh, settings, configs, Fidelity::analytic, none).predictions[0];
    CHECK(raw.error_relative < 0.0);
    CHECK(raw.sample_passes == 0);
}

TEST_CASE("A large analytic group calibrates a sample of its configurations, every point states "
          "an error, the others' from the sample's spread",
          "[sampling]") {
    const Scene scene = load_scene("cornell");
    const Bvh bvh(scene);
    RenderSettings settings = small_settings(scene);
    settings.spp = 2;  // 128 passes: the default 2 % calibrates 4 (every 32nd)
    const std::vector<HwConfig> configs = width_unit_bank_grid({4, 8, 12, 16}, {1, 2}, {16, 32});
    const PointGroupResult full = run_point_group(scene, bvh, settings, configs, Fidelity::full);
    const PointGroupResult analytic = run_point_group(scene, bvh, settings, configs, Fidelity::analytic);
    size_t calibrated = 0;
    for (size_t c = 0; c < configs.size(); ++c) {
        const Prediction& a = analytic.predictions[c];
        const double error = std::fabs(double(a.timing.cycles) / double(full.predictions[c].timing.cycles) - 1.0);
        INFO("config " << c << " analytic error " << error << " stated +-" << a.error_relative
                       << " calibrated passes " << a.sample_passes);
        CHECK(a.error_relative >= 0.0);
        CHECK(error <= a.error_relative);
        if (a.sample_passes > 0) {
            CHECK(a.sample_passes == 4);
            ++calibrated;
        }
    }
    CHECK(calibrated == 8);  // of 16: a systematic sample across the group
}

TEST_CASE("An analytic frame of fewer passes than the calibration's minimum is calibrated on all of them",
          "[sampling]") {
    const Scene scene = load_scene("cornell");
    const Bvh bvh(scene);
    RenderSettings settings = small_settings(scene);
    settings.tile = 32;
    settings.spp = 1;  // 4 passes
    const std::vector<HwConfig> configs = {HwConfig{}};
    const Prediction a = run_point_group(scene, bvh, settings, configs, Fidelity::analytic).predictions[0];
    CHECK(a.sample_passes == 4);
    CHECK(a.error_relative == 0.0);
    const Prediction f = run_point_group(scene, bvh, settings, configs, Fidelity::full).predictions[0];
    INFO("analytic " << a.timing.cycles << " full " << f.timing.cycles);
    CHECK(double(a.timing.cycles) == Approx(double(f.timing.cycles)).epsilon(0.02));
}

TEST_CASE("Configurations left out of the calibration take their stratum's ratio when a "
          "parameter splits the sample's ratios, else the sample's mean",
          "[sampling]") {
    // Widths 8/16 x units 1/2 x banks 16/32: the values varying_parameters lists (names, which
    // differ too, are no parameter to stratify by).
    const std::vector<HwConfig> configs = width_unit_bank_grid({8, 16}, {1, 2}, {16, 32});
    const std::vector<std::vector<std::string>> knobs = varying_parameters(configs);
    CHECK(knobs.size() == 8);
    CHECK(knobs[5] == std::vector<std::string>{"16", "1", "32"});  // width, units, banks
    const std::vector<size_t> calibrated = {0, 3, 4, 7};  // w8 u1 b16, w8 u2 b32, w16 u1 b16, w16 u2 b32
    const std::vector<double> half = {0.01, 0.01, 0.01, 0.01};
    const double t = student_t_quantile_two_sided(0.997, 3.0);

    // The ratio follows the unit count (1 unit near 1.05, 2 units near 0.93): units and banks
    // split the sample alike, and units, listed first, is kept; each left-out one is predicted
    // by the other of its stratum.
    {
        const std::vector<double> r = {1.05, 0.93, 1.06, 0.94};
        const auto out = uncalibrated_ratios(knobs, calibrated, r, half, 0.997);
        for (size_t c : calibrated) CHECK(out[c].second < 0.0);
        const double e[] = {1.06 / 1.05 - 1, 0.94 / 0.93 - 1, 1.05 / 1.06 - 1, 0.93 / 0.94 - 1};
        double sq = 0;
        for (double x : e) sq += x * x / 4;
        const double spread = t * std::sqrt(sq);
        CHECK(out[1].first == Approx((1.05 + 1.06) / 2));  // w8 u1 b32: the 1-unit stratum
        CHECK(out[2].first == Approx((0.93 + 0.94) / 2));  // w8 u2 b16
        CHECK(out[1].second == Approx(std::sqrt(spread * spread + 0.01 * 0.01)));
        CHECK(out[1].second < 0.1);  // the sample's mean would state about 4x that
    }
    // No parameter explains the spread: the sample's mean, with its prediction interval.
    {
        const std::vector<double> r = {1.05, 0.93, 0.93, 1.05};
        const auto out = uncalibrated_ratios(knobs, calibrated, r, half, 0.997);
        const double mean = 0.99;
        double s2 = 0;
        for (double x : r) s2 += (x - mean) * (x - mean) / 3;
        const double spread = t * std::sqrt(s2 * (1.0 + 1.0 / 4.0)) / mean;
        for (size_t c : {1, 2, 5, 6}) {
            CHECK(out[c].first == Approx(mean));
            CHECK(out[c].second == Approx(std::sqrt(spread * spread + 0.01 * 0.01)));
        }
    }
    // A calibration without an interval says nothing of the others.
    const auto unknown =
        uncalibrated_ratios(knobs, calibrated, {1.0, 1.0, 1.0, 1.0}, {0.01, -1.0, 0.01, 0.01}, 0.997);
    CHECK(unknown[1].second < 0.0);
}

TEST_CASE("Full fidelity after warm frames: the timed frame finds its scene in the caches, and "
          "counts only its own lookups",
          "[sampling]") {
    const Scene scene = load_scene("cornell");
    const Bvh bvh(scene);
    const RenderSettings settings = warm_frame_settings(scene);
    const std::vector<HwConfig> configs = {HwConfig{}};
    const Prediction cold = run_point_group(scene, bvh, settings, configs, Fidelity::full).predictions[0];
    SamplingOptions warm_options;
    warm_options.warm_frames = 1;
    const Prediction warm =
        run_point_group(scene, bvh, settings, configs, Fidelity::full, warm_options).predictions[0];
    // Cornell fits in gr08's scene caches: the warm frame took every compulsory miss.
    CHECK(cold.timing.dram_reads > 0);
    CHECK(warm.timing.dram_reads == 0);
    CHECK(warm.timing.cycles < cold.timing.cycles);
    // The same frame's lookups, the warm frame's excluded.
    REQUIRE(warm.timing.cache_hits.size() == cold.timing.cache_hits.size());
    CHECK(warm.timing.cache_hits[0] + warm.timing.cache_misses[0] ==
          cold.timing.cache_hits[0] + cold.timing.cache_misses[0]);
    CHECK(warm.timing.cache_misses[0] < cold.timing.cache_misses[0]);
    CHECK(warm.total_passes == cold.total_passes);
}

TEST_CASE("Warm frames where others fill a cache level: timed, so that their lines age",
          "[sampling]") {
    const Scene scene = load_scene("cornell");
    const Bvh bvh(scene);
    const RenderSettings settings = warm_frame_settings(scene);
    HwConfig shared_l3;  // one level, which others fill
    shared_l3.scene_memory.caches = {{"l3", 2048, 64, 16, 13.3, true}};
    SamplingOptions warm_options;
    warm_options.warm_frames = 1;
    auto run = [&](double fill_per_us, const SamplingOptions& options) {
        shared_l3.scene_memory.caches[0].foreign_fill_per_us = fill_per_us;
        return run_point_group(scene, bvh, settings, {shared_l3}, Fidelity::full, options)
            .predictions[0]
            .timing;
    };
    const FrameTiming cold = run(0.0, {});
    const FrameTiming kept = run(1.0, warm_options);  // a line lasts 32768 / 1 us: the frame
    const FrameTiming lost = run(1e6, warm_options);  // every set refilled between two lookups
    CHECK(cold.dram_reads > 0);
    CHECK(kept.dram_reads == 0);
    // Every lookup misses, warm frame or not: it left nothing the frame finds.
    CHECK(lost.dram_reads == run(1e6, {}).dram_reads);
    CHECK(lost.dram_reads > cold.dram_reads);
    CHECK(lost.cycles > kept.cycles);
    // Only the timed frame's lookups are counted, though the warm frame was timed too.
    CHECK(lost.cache_hits[0] + lost.cache_misses[0] == cold.cache_hits[0] + cold.cache_misses[0]);
}

TEST_CASE("Others' fills age a configuration's lines on its own time, whatever is timed beside it",
          "[sampling]") {
    const Scene scene = load_scene("cornell");
    const Bvh bvh(scene);
    const RenderSettings settings = warm_frame_settings(scene);
    HwConfig filled;  // lines last about as long as a pass: what is lost depends on time
    filled.scene_memory.caches = {{"l3", 64, 64, 16, 13.3, true}};
    filled.scene_memory.caches[0].foreign_fill_per_us = 200.0;
    HwConfig slow = filled;  // slower passes: alone in a group with it, `filled` would idle
    slow.scene_memory.caches[0].foreign_fill_per_us = 0.0;
    slow.scene_memory.dram_latency_ns = 2000.0;
    SamplingOptions warm_options;
    warm_options.warm_frames = 1;
    const FrameTiming alone =
        run_point_group(scene, bvh, settings, {filled}, Fidelity::full, warm_options)
            .predictions[0]
            .timing;
    const FrameTiming beside =
        run_point_group(scene, bvh, settings, {slow, filled}, Fidelity::full, warm_options)
            .predictions[1]
            .timing;
    CHECK(alone.dram_reads > 0);
    CHECK(beside.dram_reads == alone.dram_reads);
    CHECK(beside.cycles == alone.cycles);
}
