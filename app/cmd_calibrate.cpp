// sfx calibrate: the host CPU as a hardware configuration, validated on silicon.
//   --describe-host: describe the host (cpuid, caches, TSC, load latencies), microbenchmark the
//     native filters on synthetic streams, fit the per-op costs, write host.hw.yaml.
//   --check HOST.hw.yaml[,...]: for held-out workloads, the machine model's prediction from the
//     trace against the native tracer's measured core cycles (counted or estimated:
//     base/cycle_source.h; one pinned thread, trace off), each workload rendered until its
//     fastest renders agree (base/convergence.h) or its budget runs out; one host file per back
//     end (its SIMD width), all measured in turn per cell; then per scene and back end, what the
//     branch predictor saves a tile's traversal (kernels/stream/stream_microbench.h).

#include <sched.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <fstream>
#include <iostream>
#include <map>
#include <memory>
#include <nlohmann/json.hpp>

#include "app/commands.h"
#include "app/progress.h"
#include "base/core_clock.h"
#include "base/core_contention.h"
#include "base/input_error.h"
#include "base/strict_number.h"
#include "base/user_files.h"
#include "kernels/bvh.h"
#include "kernels/stream/stream_microbench.h"
#include "sweeps/host_calibration.h"
#include "workloads/scene_loader.h"

namespace sfx {

namespace {

// A misprediction's cost in one loop as fitted ("-": not fitted, the pooled cost).
std::string loop_cost_text(double cycles) {
    char text[32];
    std::snprintf(text, sizeof text, "%.1f", cycles);
    return cycles >= 0 ? text : "-";
}

std::vector<std::string> split(const std::string& s) {
    std::vector<std::string> out;
    size_t start = 0;
    while (start <= s.size()) {
        const size_t comma = s.find(',', start);
        out.push_back(
            s.substr(start, comma == std::string::npos ? std::string::npos : comma - start));
        if (comma == std::string::npos) break;
        start = comma + 1;
    }
    return out;
}

uint32_t parse_count(const std::string& text, const std::string& flag, uint64_t lo, uint64_t hi) {
    uint64_t v = 0;
    if (!parse_unsigned(text, v) || v < lo || v > hi)
        throw InputError("command line", 0, flag,
                         "expected an integer in [" + std::to_string(lo) + ", " +
                             std::to_string(hi) + "], got '" + text + "'");
    return uint32_t(v);
}

std::pair<uint32_t, uint32_t> parse_res(const std::string& text) {
    const size_t x = text.find('x');
    if (x == std::string::npos)
        throw InputError("command line", 0, "--res", "expected WxH, got '" + text + "'");
    return {parse_count(text.substr(0, x), "--res", 1, 16384),
            parse_count(text.substr(x + 1), "--res", 1, 16384)};
}

const char* k_stage_names[3] = {"traversal", "intersection", "shading"};

}  // namespace

void add_calibrate_command(CLI::App& app) {
    struct Options {
        bool describe = false;
        std::string output = "host.hw.yaml";
        std::string memory_from;
        std::string few_ray_from;
        std::string branch_model = "unseen_ops";
        std::string check;
        std::string isa = "auto";
        uint32_t repeats = 41;
        uint32_t min_repeat = 7;
        uint32_t fastest = 3;
        std::string tolerance = "0.03";
        std::string contention_wait = "600";
        std::string scenes = "cornell,furnace,atrium,conference,temple";
        std::string tiles = "16,32,64";
        std::string res = "64x64,128x128";
        uint32_t spp = 1;
        uint32_t repeat = 31;
        bool json = false;
        bool memory_now = false;
    };
    auto o = std::make_shared<Options>();
    CLI::App* c = app.add_subcommand(
        "calibrate", "the host CPU as a hardware configuration: describe and fit it, or check it");
    c->add_flag("--describe-host", o->describe,
                "describe the host, fit its per-op costs on microbenchmarks, write -o");
    c->add_option("-o,--output", o->output, "the host configuration written by --describe-host")
        ->capture_default_str();
    c->add_option("--memory-from", o->memory_from,
                  "--describe-host: take the scene memory (caches, their latencies, the L3 this "
                  "core keeps, DRAM) from this host file of the same machine instead of "
                  "measuring it, so that every back end's file describes one memory");
    c->add_option("--few-ray-from", o->few_ray_from,
                  "--describe-host, a back end of 8 lanes or more: take the few-ray loop's "
                  "costs (its box test's, its entry's, its mispredictions') and the one-ray and "
                  "few-ray loops' exposed share of a node read from this host file of another "
                  "such back end of the same machine instead of fitting them: those loops run "
                  "the same code at every such width");
    c->add_option("--branch-model", o->branch_model,
                  "--describe-host: how the model prices a traversal's branches, fitted on the "
                  "branch microbenchmark: tage (L-TAGE's TAGE run over the traversal's branches, "
                  "a cost per misprediction) or unseen_ops (a cost per op of a traversal not just "
                  "run, by loop; hw_model/branch_predictor.h)")
        ->check(CLI::IsMember({"tage", "unseen_ops"}))
        ->capture_default_str();
    c->add_option("--check", o->check,
                  "HOST.hw.yaml[,MORE.hw.yaml]: predict and measure the native tracer's cycles "
                  "per workload, each file on the back end of its SIMD width");
    c->add_option("--isa", o->isa, "auto, avx512, avx2 or scalar: the back end measured")
        ->capture_default_str();
    c->add_option("--microbench-repeats", o->repeats,
                  "most repetitions per microbenchmark point (it stops when converged)")
        ->capture_default_str();
    c->add_option("--fastest", o->fastest,
                  "converged: the fastest K samples of a render or microbenchmark agree")
        ->capture_default_str();
    c->add_option("--tolerance", o->tolerance,
                  "converged: the K-th fastest within (1 + this) x the fastest (0.03: 3 %)")
        ->capture_default_str();
    c->add_option("--contention-wait", o->contention_wait,
                  "seconds spent in all waiting for a core no other hardware thread shares "
                  "(base/core_contention.h); after that, samples are taken as they come")
        ->capture_default_str();
    c->add_option("--min-repeat", o->min_repeat, "--check: renders per workload at least")
        ->capture_default_str();
    c->add_option("--scenes", o->scenes, "--check: comma-separated scenes")->capture_default_str();
    c->add_option("--tiles", o->tiles, "--check: comma-separated tile sizes")
        ->capture_default_str();
    c->add_option("--res", o->res, "--check: comma-separated resolutions WxH")
        ->capture_default_str();
    c->add_option("--spp", o->spp, "--check: samples per pixel")->capture_default_str();
    c->add_option("--repeat", o->repeat,
                  "--check: renders per workload at most (the budget; it stops when converged)")
        ->capture_default_str();
    c->add_flag("--memory-now", o->memory_now,
                "--check: predict each workload with the L3 this core kept in the round of its "
                "fastest render (chased again at the start of every round) instead of the host "
                "file's; the file's prediction is kept beside it");
    c->add_flag("--json", o->json, "print one JSON document");
    c->callback([o] {
        if (o->describe == !o->check.empty())
            throw InputError("command line", 0, "--describe-host",
                             "give exactly one of --describe-host and --check");
        const Isa isa = resolve_isa(parse_isa(o->isa));
        if (o->repeats < 1 || o->repeats > 1000)
            throw InputError("command line", 0, "--microbench-repeats", "expected 1 to 1000");
        if (o->repeat < 1 || o->repeat > 1000)
            throw InputError("command line", 0, "--repeat", "expected 1 to 1000");
        double tolerance = 0.0;
        if (!parse_finite(o->tolerance, tolerance) || tolerance < 0.0 || tolerance > 1.0)
            throw InputError("command line", 0, "--tolerance",
                             "expected a fraction from 0 to 1 (0.03 is 3 %), got '" +
                                 o->tolerance + "'");
        double contention_wait = 0.0;
        if (!parse_finite(o->contention_wait, contention_wait) || contention_wait < 0.0 ||
            contention_wait > 86400.0)
            throw InputError("command line", 0, "--contention-wait",
                             "expected seconds from 0 to 86400, got '" + o->contention_wait + "'");
        core_contention().set_total_wait_ms(1000.0 * contention_wait);
        if (o->fastest < 1 || o->fastest > o->repeat || (o->describe && o->fastest > o->repeats))
            throw InputError("command line", 0, "--fastest",
                             "expected 1 to the budget (--repeat, --microbench-repeats), got " +
                                 std::to_string(o->fastest));
        ConvergenceRule render_rule;
        render_rule.fastest = o->fastest;
        render_rule.tolerance = tolerance;
        render_rule.min_samples = o->min_repeat;
        render_rule.budget = o->repeat;
        check_rule(render_rule, o->min_repeat > o->repeat ? "--min-repeat" : "--repeat");
        ConvergenceRule bench_rule = microbench_rule(o->repeats);
        bench_rule.fastest = std::min(o->fastest, o->repeats);
        bench_rule.tolerance = tolerance;
        if (o->spp < 1 || o->spp > 4096)
            throw InputError("command line", 0, "--spp", "expected 1 to 4096");
        const bool pinned = pin_to_current_cpu();
        const int cpu = sched_getcpu();  // the rows say where they were measured
        if (!o->memory_from.empty() && !o->describe)
            throw InputError("command line", 0, "--memory-from", "only with --describe-host");
        if (!o->few_ray_from.empty() && !o->describe)
            throw InputError("command line", 0, "--few-ray-from", "only with --describe-host");
        if (o->memory_now && o->check.empty())
            throw InputError("command line", 0, "--memory-now", "only with --check");
        if (o->describe) {
            std::unique_ptr<HwConfig> memory_from;
            if (!o->memory_from.empty())
                memory_from = std::make_unique<HwConfig>(load_hw_config(o->memory_from));
            std::unique_ptr<FewRayFrom> few_ray_from;
            if (!o->few_ray_from.empty()) {
                try {
                    few_ray_from = std::make_unique<FewRayFrom>(
                        few_ray_costs_from(load_hw_config(o->few_ray_from), o->few_ray_from, isa));
                } catch (const std::invalid_argument& e) {
                    throw InputError(o->few_ray_from, 0, "--few-ray-from", e.what());
                }
                if (few_ray_from->branch_model != o->branch_model)
                    throw InputError(o->few_ray_from, 0, "--few-ray-from",
                                     "its branch_predictor kind is " + few_ray_from->branch_model +
                                         ", not the --branch-model " + o->branch_model +
                                         " fitted here");
            }
            OutputFiles outputs;
            const std::string temp = outputs.add(o->output, "--output");
            Progress progress("calibrate", 15, "op kinds");
            const HostCalibration cal = calibrate_host(
                isa, bench_rule,
                [&](uint32_t done, uint32_t total) {
                    progress.set_total(total);
                    progress.set_done(done);
                },
                memory_from.get(), o->memory_from, few_ray_from.get(), o->branch_model);
            progress.finish();
            std::ofstream(temp) << cal.yaml;
            parse_hw_config(cal.yaml, o->output);  // what was written reads back
            outputs.commit();
            if (o->json) {
                nlohmann::json j;
                j["output"] = o->output;
                j["tsc_mhz"] = cal.host.tsc_mhz;
                j["simd_width"] = cal.host.simd_width;
                j["pinned"] = pinned;
                j["speed_probe_start_cycles"] = cal.speed_probe_start_cycles;
                j["speed_probe_cycles"] = cal.host.speed_probe_cycles;
                j["speed_probe_drift"] =
                    speed_probe_drift(cal.host.speed_probe_cycles, cal.speed_probe_start_cycles);
                j["sweep_probe_points_cycles"] = cal.sweep_probe_points_cycles;
                j["calibration_drift"] = calibration_drift(cal);
                j["microarchitecture"] = describe(cal.host.microarchitecture);
                j["convergence_rule"] = describe(bench_rule);
                j["converged_points"] = cal.converged_points;
                j["contended_samples"] = core_contention().set_aside();
                j["unshared_adds_per_tick"] = core_contention().best();
                j["contention_gate_spent"] = core_contention().open();
                j["points"] = cal.points;
                for (size_t i = 0; i < cal.op_costs.size(); ++i) {
                    const OpCostConfig& k = cal.op_costs[i];
                    j["op_costs"][k.op] = {
                        {"per_op", k.per_op_cycles},
                        {"per_group", k.per_group_cycles},
                        {"per_lane", k.per_lane_cycles},
                        {"per_pass", k.per_pass_cycles},
                        {"per_fail", k.per_fail_cycles},
                        {"per_minority_lane", k.per_minority_lane_cycles},
                        {"beyond_l1_per_lane", k.beyond_l1_per_lane_cycles},
                        {"beyond_l2_per_lane", k.beyond_l2_per_lane_cycles},
                        {"beyond_l1_skipping_per_lane", k.beyond_l1_skipping_per_lane_cycles},
                        {"beyond_tlb_per_lane", k.beyond_tlb_per_lane_cycles},
                        {"one_lane", k.one_lane_cycles},
                        {"one_lane_pass", k.one_lane_pass_cycles},
                        {"one_lane_failed_candidate", k.one_lane_failed_candidate_cycles},
                        {"few_lane", k.few_lane_cycles},
                        {"one_ray_entry", k.one_ray_entry_cycles},
                        {"few_ray_entry", k.few_ray_entry_cycles},
                        {"traversal_start", k.traversal_start_cycles},
                        {"shared_origin_per_lane", k.shared_origin_per_lane_cycles},
                        {"thin_lens_per_lane", k.thin_lens_per_lane_cycles},
                        {"sphere_light_per_pass", k.sphere_light_per_pass_cycles},
                        {"per_failed_candidate", k.per_failed_candidate_cycles},
                        {"sphere_hit_per_lane", k.sphere_hit_per_lane_cycles},
                        {"cold_call", k.cold_call_cycles},
                        {"filter_per_op", cal.filter_costs[i].per_op_cycles},
                        {"fit_median_error", cal.fit_errors[i].first},
                        {"fit_worst_error", cal.fit_errors[i].second}};
                    for (size_t b = 0; b < cal.residual_buffer_slots.size(); ++b)
                        if (!std::isnan(cal.residuals_by_buffer[i][b]))
                            j["op_costs"][k.op]["residual_by_buffer"]
                             [std::to_string(cal.residual_buffer_slots[b])] =
                                 cal.residuals_by_buffer[i][b];
                    for (size_t l = 0; l < cal.residual_lengths.size(); ++l)
                        if (!std::isnan(cal.residuals_by_length[i][l]))
                            j["op_costs"][k.op]["residual_by_length"]
                             [std::to_string(cal.residual_lengths[l])] =
                                 cal.residuals_by_length[i][l];
                }
                for (const MicrobenchSample& m : cal.samples)
                    j["samples"].push_back(
                        {{"op", to_string(m.kind)},
                         {"slots", m.slots},
                         {"lanes", m.lanes},
                         {"passed", m.passed},
                         {"cycles", m.cycles},
                         {"converged", m.converged},
                         {"repetitions", m.repetitions},
                         {"thin_lens", m.thin_lens},
                         {"sphere_light", m.sphere_light},
                         {"failing_candidates", m.failing_candidates},
                         {"failed_candidates", m.failed_candidates},
                         {"sphere_hits", m.sphere_hits},
                         {"cold_call_cycles", m.cold_call_timed ? nlohmann::json(m.cold_call_cycles)
                                                                : nlohmann::json()}});
                for (size_t i = 0; i < cal.cold_traversal_cycles.size(); ++i)
                    j["cold_traversals"].push_back({{"lanes", cal.cold_traversal_lengths[i]},
                                                    {"cycles", cal.cold_traversal_cycles[i]}});
                j["one_lane_fit_median_error"] = cal.short_stream_fit_errors.first;
                j["one_lane_fit_worst_error"] = cal.short_stream_fit_errors.second;
                for (size_t i = 0; i < cal.one_ray_samples.size(); ++i) {
                    const OneRaySample& s = cal.one_ray_samples[i];
                    const OneLaneSample& fitted = cal.short_stream_samples[i];
                    nlohmann::json ops, few_ops, one_lane_passed,
                        stream_ops = nlohmann::json::array();
                    for (uint32_t k = 0; k < k_op_kind_count; ++k) {
                        if (s.ops[k]) ops[to_string(OpKind(k))] = s.ops[k];
                        if (s.one_lane_passed[k])
                            one_lane_passed[to_string(OpKind(k))] = s.one_lane_passed[k];
                        if (s.few_ops[k]) few_ops[to_string(OpKind(k))] = s.few_ops[k];
                    }
                    for (const OpsOfLength& o : s.stream_ops)
                        stream_ops.push_back({{"op", to_string(o.kind)},
                                              {"lanes", o.lanes},
                                              {"count", o.count},
                                              {"passed", o.passed},
                                              {"failed_candidates", o.failed_candidates}});
                    j["one_ray_samples"].push_back(
                        {{"rays", s.rays},
                         {"streams", s.streams},
                         {"entry_depth", s.entry_depth},
                         {"entries", {s.entries[0], s.entries[1]}},
                         {"ops", ops},
                         {"few_ops", few_ops},
                         {"few_ray_one_lane_box_ops", s.few_ray_one_lane_box_ops},
                         {"stream_ops", stream_ops},
                         {"cycles", s.cycles},
                         {"converged", s.converged},
                         {"repetitions", s.repetitions},
                         {"modelled_mispredictions", s.modelled_mispredictions},
                         {"one_lane_passed", one_lane_passed},
                         {"leaf_share", s.leaf_share},
                         // The leaf tests as the fit prices them, against the stage
                         // clock's leaf share.
                         {"leaf_priced_cycles", fitted.leaf_op_cycles},
                         {"one_ray_loop_share", s.short_loop_share[0]},
                         {"few_ray_loop_share", s.short_loop_share[1]},
                         // Priced before the fit (the leaf tests,
                         // the stream loop's groups and lanes, the
                         // mispredictions), and all the fit's price.
                         {"priced_cycles", fitted.stream_op_cycles},
                         {"fitted_cycles", short_stream_cycles(cal.short_stream_costs, fitted)}});
                }
                j["hit_read_exposed_share"] = cal.hit_read_fit.share;
                j["hit_read_fit_median_error"] = cal.hit_read_fit.error.first;
                j["hit_read_fit_worst_error"] = cal.hit_read_fit.error.second;
                for (size_t i = 0; i < cal.surface_read_samples.size(); ++i) {
                    const SurfaceReadSample& s = cal.surface_read_samples[i];
                    j["surface_read_samples"].push_back(
                        {{"triangles", s.triangles},
                         {"lanes", s.lanes},
                         {"cycles", s.cycles},
                         {"resident_cycles", s.resident_cycles},
                         {"modeled_beyond_l1_cycles", cal.hit_read_fit.modeled[i]},
                         {"converged", s.converged},
                         {"repetitions", s.repetitions}});
                }
                j["branch_predictor"] = cal.host.branch_predictor.kind;
                j["mispredict_cycles"] = cal.host.branch_predictor.mispredict_cycles;
                j["loop_mispredict_cycles"] = {cal.host.branch_predictor.one_ray_mispredict_cycles,
                                               cal.host.branch_predictor.few_ray_mispredict_cycles,
                                               cal.host.branch_predictor.stream_mispredict_cycles};
                for (const PredictorCheck& b : cal.branch_samples) {
                    const PredictorStates& m = modelled_states(b, cal.host.branch_predictor.kind);
                    j["branch_samples"].push_back(
                        {{"bounce", b.measured.bounce},
                         {"batches", b.measured.batches},
                         {"converged_batches", b.measured.converged_batches},
                         {"primed_cycles", b.measured.primed.cycles},
                         {"cached_cycles", b.measured.cached.cycles},
                         {"displaced_cycles", b.measured.displaced.cycles},
                         {"branches", m.branches},
                         {"primed_mispredictions", m.primed},
                         {"displaced_mispredictions", m.displaced}});
                }
                j["node_read_exposed_share"] = cal.node_read_fit.share;
                j["node_read_share_given"] = cal.node_read_fit.given;
                j["node_read_own_share"] = cal.node_read_fit.own_share;
                j["node_read_fit_median_error"] = cal.node_read_fit.error.first;
                j["node_read_fit_worst_error"] = cal.node_read_fit.error.second;
                for (size_t i = 0; i < cal.branch_samples.size(); ++i) {
                    const PredictorSample& m = cal.branch_samples[i].measured;
                    j["node_read_samples"].push_back(
                        {{"bounce", m.bounce},
                         {"evicted_loop_cycles", m.evicted.loops},
                         {"primed_loop_cycles", m.primed.loops},
                         {"measured_extra_cycles", cal.node_read_fit.measured[i]},
                         {"modeled_whole_extra_cycles", cal.node_read_fit.modeled_whole[i]},
                         {"modeled_extra_cycles", cal.node_read_fit.modeled[i]}});
                }
                for (const PredictorSample& b : cal.eviction_baseline)
                    j["eviction_baseline"].push_back({{"bounce", b.bounce},
                                                      {"evicted_loop_cycles", b.evicted.loops},
                                                      {"primed_loop_cycles", b.primed.loops}});
                for (const KernelRate& r : cal.rates)
                    j["rates"].push_back({{"what", r.what},
                                          {"slots", r.slots},
                                          {"lanes", r.lanes},
                                          {"scattered", r.scattered},
                                          {"cycles_per_lane", r.cycles_per_lane}});
                std::cout << j.dump(2) << "\n";
                return;
            }
            std::printf(
                "host: %s, %s, TSC %.1f MHz, core %.1f MHz (%s chain), %zu cache "
                "levels%s\n",
                describe(cal.host.microarchitecture).c_str(), cal.host.isa.c_str(),
                cal.host.tsc_mhz, cal.host.core_mhz, clock_chain_name(cal.host.simd_width),
                cal.host.caches.size(), pinned ? ", pinned" : ", NOT pinned");
            std::printf("first-level DTLB: %u pages (%s)\n", cal.host.dtlb.pages,
                        describe(cal.host.dtlb).c_str());
            std::printf(
                "microbenchmarks: %u of %u points converged (%s in each of %u sweeps, "
                "judged over all)\n",
                cal.converged_points, cal.points, describe(bench_rule).c_str(),
                cal.microbench_visits);
            std::printf(
                "core shared with another hardware thread after %u samples, which were set "
                "aside and the core waited for (independent adds: %.2f a TSC tick unshared)\n",
                core_contention().set_aside(), core_contention().best());
            if (core_contention().open())
                std::printf(
                    "  the gate's total wait was spent: later samples were taken as "
                    "they came\n");
            const double drift =
                speed_probe_drift(cal.host.speed_probe_cycles, cal.speed_probe_start_cycles);
            const double moved = calibration_drift(cal);
            std::printf(
                "speed probe: %.0f cycles before the microbenchmarks, %.0f after (drift %+.1f "
                "%%); its points in the microbenchmarks' sweeps %.0f (%+.1f %% from the probe "
                "after)%s\n",
                cal.speed_probe_start_cycles, cal.host.speed_probe_cycles, 100.0 * drift,
                cal.sweep_probe_points_cycles,
                100.0 *
                    speed_probe_drift(cal.sweep_probe_points_cycles, cal.host.speed_probe_cycles),
                std::abs(moved) > k_speed_probe_tolerance
                    ? ": the machine moved during calibration, calibrate again"
                    : "");
            std::printf("%-20s %9s %9s %9s %9s %9s %9s %9s %9s %9s %9s %8s %8s %9s %9s\n",
                        "op kind", "per_op", "per_group", "per_lane", "per_pass", "per_fail",
                        "minority", "beyondL1", "skipL1", "beyondL2", "beyondTLB", "fit med",
                        "fit max", "one_lane", "few_lane");
            for (size_t i = 0; i < cal.op_costs.size(); ++i) {
                const OpCostConfig& k = cal.op_costs[i];
                std::printf(
                    "%-20s %9.1f %9.1f %9.1f %9.1f %9.1f %9.1f %9.1f %9.1f %9.1f %9.1f %7.1f%% "
                    "%7.1f%% %9.1f %9.1f\n",
                    k.op.c_str(), k.per_op_cycles, k.per_group_cycles, k.per_lane_cycles,
                    k.per_pass_cycles, k.per_fail_cycles, k.per_minority_lane_cycles,
                    k.beyond_l1_per_lane_cycles, k.beyond_l1_skipping_per_lane_cycles,
                    k.beyond_l2_per_lane_cycles, k.beyond_tlb_per_lane_cycles,
                    100 * cal.fit_errors[i].first, 100 * cal.fit_errors[i].second,
                    k.one_lane_cycles, k.few_lane_cycles);
            }
            // Each fitted kind's residuals, one column per key.
            auto print_residuals = [&](const std::vector<uint32_t>& keys, const char* unit,
                                       const std::vector<std::vector<double>>& residuals) {
                for (const uint32_t key : keys) std::printf(" %u", key);
                std::printf(" %s\n", unit);
                for (size_t i = 0; i < cal.op_costs.size(); ++i) {
                    std::printf("  %-20s", cal.op_costs[i].op.c_str());
                    for (const double r : residuals[i])
                        std::isnan(r) ? std::printf("        -")
                                      : std::printf(" %+7.1f%%", 100 * r);
                    std::printf("\n");
                }
            };
            std::printf("fit error by buffer (median of priced / measured - 1) at");
            print_residuals(cal.residual_buffer_slots, "slots", cal.residuals_by_buffer);
            std::printf("fit error at %u slots by stream length:",
                        cal.residual_buffer_slots.empty()
                            ? 0u
                            : *std::max_element(cal.residual_buffer_slots.begin(),
                                                cal.residual_buffer_slots.end()));
            print_residuals(cal.residual_lengths, "lanes", cal.residuals_by_length);
            for (const OpCostConfig& k : cal.op_costs)
                if (k.per_failed_candidate_cycles > 0)
                    std::printf(
                        "%s: a candidate that fails its full test adds %.1f cycles to a "
                        "lane the float stage rejects\n",
                        k.op.c_str(), k.per_failed_candidate_cycles);
            for (const OpCostConfig& k : cal.op_costs)
                if (k.sphere_hit_per_lane_cycles != 0)
                    std::printf(
                        "%s: a lane whose hit is a sphere costs %+.1f cycles against one whose hit "
                        "is a triangle (%.1f a lane with its share of a full group)\n",
                        k.op.c_str(), k.sphere_hit_per_lane_cycles,
                        k.per_lane_cycles + k.per_group_cycles / std::max(1u, cal.host.simd_width));
            for (const OpCostConfig& k : cal.op_costs)
                if (k.cold_call_cycles > 0)
                    std::printf(
                        "%s: %s cold (as a frame's) costs %.1f cycles over one right "
                        "after another\n",
                        k.op.c_str(),
                        op_kind_named(k.op) == OpKind::box_test ? "a traversal's start" : "a call",
                        k.cold_call_cycles);
            for (const OpCostConfig& k : cal.op_costs)
                if (k.one_lane_pass_cycles > 0 || k.one_lane_failed_candidate_cycles > 0)
                    std::printf(
                        "%s: one lane that fails costs %.1f cycles; passing adds %.1f, a failed "
                        "candidate %.1f\n",
                        k.op.c_str(), k.one_lane_cycles, k.one_lane_pass_cycles,
                        k.one_lane_failed_candidate_cycles);
            std::printf(
                "one- and few-lane costs, and the stream loop's per-op box cost: %zu batches of "
                "traversals, fit error median %.1f%%, worst %.1f%%\n",
                cal.one_ray_samples.size(), 100 * cal.short_stream_fit_errors.first,
                100 * cal.short_stream_fit_errors.second);
            double mispredictions = 0.0, batch_cycles = 0.0;
            for (const OneRaySample& s : cal.one_ray_samples) {
                mispredictions += s.modelled_mispredictions;
                batch_cycles += s.cycles;
            }
            const double mispredict = cal.host.branch_predictor.mispredict_cycles;
            std::printf(
                "  the model's predictor on those batches: %.0f mispredictions, %.1f%% of "
                "their cycles at %.1f each, priced before the fit\n",
                mispredictions,
                batch_cycles > 0 ? 100 * mispredictions * mispredict / batch_cycles : 0.0,
                mispredict);
            // Where the fit puts the batches' cycles, against the stage clock's split of them.
            const ShortStreamSplit split =
                short_stream_split(cal.short_stream_costs, cal.short_stream_samples,
                                   cal.one_ray_samples, cal.host.branch_predictor);
            std::printf(
                "  by the stage clock (the fastest cycles split by 5 clocked repetitions' "
                "shares), measured / priced Mcycles:");
            const std::pair<const char*, const ShortStreamPart*> parts[] = {
                {"one-ray loop", &split.one_ray},
                {"few-ray loop", &split.few_ray},
                {"leaf tests", &split.leaves},
                {"the rest", &split.rest}};
            for (size_t i = 0; i < std::size(parts); ++i)
                std::printf("%s %s %.3f / %.3f", i ? ";" : "", parts[i].first,
                            parts[i].second->measured / 1e6, parts[i].second->priced / 1e6);
            std::printf("\n");
            for (const OpCostConfig& k : cal.op_costs)
                if (k.op == "box_test")
                    std::printf(
                        "entering the one-ray loop %.1f cycles, the few-ray loop %.1f; "
                        "starting a traversal %.1f; checking a shared origin %.2f a lane "
                        "(timed by itself%s)\n",
                        k.one_ray_entry_cycles, k.few_ray_entry_cycles, k.traversal_start_cycles,
                        k.shared_origin_per_lane_cycles,
                        cal.shared_origin.converged ? "" : ", NOT converged");
            for (size_t i = 0; i < cal.op_costs.size(); ++i)
                if (cal.op_costs[i].per_op_cycles != cal.filter_costs[i].per_op_cycles)
                    std::printf("  %s per_op: %.1f in a traversal (above), %.1f in the filter "
                                "microbenchmarks' independent calls (their fit error)\n",
                                cal.op_costs[i].op.c_str(), cal.op_costs[i].per_op_cycles,
                                cal.filter_costs[i].per_op_cycles);
            const BranchPredictorConfig& bp = cal.host.branch_predictor;
            std::printf(
                "branch mispredictions (the model's predictor, %s): %.1f cycles each; a box "
                "test's by loop %s / %s / %s (one-ray / few-ray / stream; -: the pooled), from "
                "the branch microbenchmark:\n",
                bp.kind.c_str(), bp.mispredict_cycles,
                loop_cost_text(bp.one_ray_mispredict_cycles).c_str(),
                loop_cost_text(bp.few_ray_mispredict_cycles).c_str(),
                loop_cost_text(bp.stream_mispredict_cycles).c_str());
            for (const PredictorCheck& b : cal.branch_samples) {
                const PredictorStates& m = modelled_states(b, bp.kind);
                std::printf(
                    "  %-7s cycles primed %.0f, cached %.0f, displaced %.0f (%u of %u "
                    "batches converged); model: %llu branches, mispredicted %llu "
                    "primed, %llu displaced\n",
                    b.measured.bounce ? "bounces" : "camera", b.measured.primed.cycles,
                    b.measured.cached.cycles, b.measured.displaced.cycles,
                    b.measured.converged_batches, b.measured.batches,
                    (unsigned long long)m.branches, (unsigned long long)m.primed,
                    (unsigned long long)m.displaced);
            }
            const std::string share_source =
                cal.node_read_fit.given ? " (as " + o->few_ray_from + " gives it)" : "";
            std::printf(
                "node reads of the one-ray and few-ray loops: exposed share %.3f of "
                "the model's latency beyond an L1D hit%s, fit error median %.1f%%, worst "
                "%.1f%%",
                cal.node_read_fit.share, share_source.c_str(), 100 * cal.node_read_fit.error.first,
                100 * cal.node_read_fit.error.second);
            if (cal.node_read_fit.given)
                std::printf("; these batches alone fit %.3f", cal.node_read_fit.own_share);
            std::printf("\n");
            for (size_t i = 0; i < cal.branch_samples.size(); ++i)
                std::printf(
                    "  %-7s from DRAM, short loops: measured +%.0f cycles beyond the "
                    "synthetic scene's; model +%.0f with the whole latency, +%.0f at the "
                    "share\n",
                    cal.branch_samples[i].measured.bounce ? "bounces" : "camera",
                    cal.node_read_fit.measured[i], cal.node_read_fit.modeled_whole[i],
                    cal.node_read_fit.modeled[i]);
            std::printf("hit reads beyond the caches: exposed share %.3f of the cache model's "
                        "latency, fit error median %.1f%%, worst %.1f%%\n",
                        cal.hit_read_fit.share, 100 * cal.hit_read_fit.error.first,
                        100 * cal.hit_read_fit.error.second);
            std::printf("%-10s %9s %12s %12s %14s %6s\n", "triangles", "lanes", "cycles/lane",
                        "resident", "modelled extra", "conv");
            for (size_t i = 0; i < cal.surface_read_samples.size(); ++i) {
                const SurfaceReadSample& s = cal.surface_read_samples[i];
                std::printf("%-10u %9u %12.1f %12.1f %14.1f %6s\n", s.triangles, s.lanes,
                            s.cycles / s.lanes, s.resident_cycles / s.lanes,
                            cal.hit_read_fit.modeled[i] / s.lanes, s.converged ? "yes" : "NO");
            }
            std::printf("\n%-30s %6s %6s %9s %12s\n", "kernel", "slots", "lanes", "slots are",
                        "cycles/lane");
            for (const KernelRate& r : cal.rates)
                std::printf("%-30s %6u %6u %9s %12.2f\n", r.what, r.slots, r.lanes,
                            r.scattered ? "random" : "in order", r.cycles_per_lane);
            std::printf("\nwrote %s\n", o->output.c_str());
            return;
        }

        // One host file per back end: each is measured with the back end of its SIMD width.
        std::vector<HwConfig> hosts;
        std::vector<Isa> host_isas;
        for (const std::string& path : split(o->check)) {
            hosts.push_back(load_hw_config(path));
            const HwConfig& host = hosts.back();
            if (host.op_costs.empty())
                throw InputError(
                    path, 0, "op_costs",
                    "no fitted per-op costs (write it with sfx calibrate --describe-host)");
            Isa by_width = Isa::automatic;
            for (const Isa candidate : {Isa::scalar, Isa::avx2, Isa::avx512})
                if (isa_width(candidate) == host.simd.width) by_width = candidate;
            if (by_width == Isa::automatic || !isa_supported(by_width))
                throw InputError(path, 0, "simd.width",
                                 std::to_string(host.simd.width) +
                                     " lanes: no stream back end of that width runs on this CPU");
            if (parse_isa(o->isa) != Isa::automatic && isa != by_width)
                throw InputError("command line", 0, "--isa",
                                 std::string(isa_name(isa)) + " does not match " + path +
                                     " (simd.width " + std::to_string(host.simd.width) + ")");
            host_isas.push_back(by_width);
        }
        std::vector<uint32_t> tiles;
        for (const std::string& t : split(o->tiles))
            tiles.push_back(parse_count(t, "--tiles", 1, 4096));
        std::vector<std::pair<uint32_t, uint32_t>> resolutions;
        for (const std::string& r : split(o->res)) resolutions.push_back(parse_res(r));
        const std::vector<std::string> scenes = split(o->scenes);
        // Every scene loaded first: the workloads of all scenes are measured in one
        // interleaved run (predict_and_measure), so that each one's renders span the run.
        std::vector<std::unique_ptr<Scene>> loaded;
        std::vector<std::unique_ptr<Bvh>> bvhs;
        // Counted in scenes while loading, then in workloads (predicted, then converged).
        Progress progress("calibrate --check", scenes.size(), "scenes, then workloads");
        for (const std::string& name : scenes) {
            progress.set_label(name + ": loading");
            loaded.push_back(std::make_unique<Scene>(load_scene(name)));
            bvhs.push_back(std::make_unique<Bvh>(*loaded.back()));
            progress.advance();
        }
        // Every tile on every back end of every (scene, resolution) cell.
        std::vector<SiliconVariant> variants;
        std::vector<size_t> variant_scene;  // index into scenes
        for (size_t sc = 0; sc < scenes.size(); ++sc)
            for (const auto& [w, h] : resolutions)
                for (size_t k = 0; k < hosts.size(); ++k)
                    for (uint32_t tile : tiles) {
                        SiliconVariant v;
                        v.scene = loaded[sc].get();
                        v.bvh = bvhs[sc].get();
                        v.settings.width = w;
                        v.settings.height = h;
                        v.settings.spp = o->spp;
                        v.settings.tile = tile;
                        v.settings.max_depth = loaded[sc]->max_depth;
                        v.settings.isa = host_isas[k];
                        v.host = &hosts[k];
                        // From cold caches too, on one tile (the middle one listed): enough
                        // to see what the frame pays for what the render before left.
                        v.cold = tile == tiles[tiles.size() / 2];
                        variants.push_back(v);
                        variant_scene.push_back(sc);
                    }
        const std::vector<SiliconMeasurement> measured = predict_and_measure(
            variants, render_rule, 1,
            [&](const std::string& what, size_t done, size_t total) {
                progress.set_label(what);
                progress.set_total(total);
                progress.set_done(done);
            },
            o->memory_now);
        // What the branch predictor saves a traversal it has just run, per scene and back end,
        // beside what the model's predictor makes of the same batches (check_predictor; each
        // back end's host file prices its mispredictions), and in the synthetic scene whose
        // traversals the per-op costs come from (at scene index scenes.size(), measured only).
        // The model also times the batches from empty caches and after themselves
        // (model_batch_memory), against their evicted and primed states.
        // Counted apart from the workloads: a scene's check took about a minute on each back end
        // of an Intel Xeon VM (2026-12-06), while the workloads' count showed its last ETA, of
        // seconds, through all of them.
        std::map<std::pair<size_t, Isa>, std::vector<PredictorCheck>> predictor;
        std::map<std::pair<size_t, Isa>, std::vector<BatchMemoryCycles>> batch_memory;
        progress.clear();
        Progress checks("calibrate --check", host_isas.size() * (scenes.size() + 1),
                        "branch-predictor checks (a scene on a back end)");
        for (size_t k = 0; k < host_isas.size(); ++k) {
            const Isa isa = host_isas[k];
            for (size_t sc = 0; sc < scenes.size(); ++sc) {
                checks.set_label(scenes[sc] + ": the branch predictor, " + isa_name(isa));
                predictor[{sc, isa}] = check_predictor(*loaded[sc], *bvhs[sc], isa, bench_rule);
                for (PredictorCheck& c : predictor[{sc, isa}]) {
                    batch_memory[{sc, isa}].push_back(model_batch_memory(hosts[k], c, true));
                    c.batches.clear();  // their memory, no longer needed
                }
                checks.advance();
            }
            checks.set_label(std::string("the synthetic scene's branch predictor, ") +
                             isa_name(isa));
            for (const PredictorSample& p : run_predictor_microbenchmarks(isa, bench_rule))
                predictor[{scenes.size(), isa}].push_back(
                    {p, PredictorStates{}, PredictorStates{}, {}, {}});
            checks.advance();
        }
        checks.finish();
        const Microarchitecture uarch = read_microarchitecture();
        uint32_t workloads = 0, converged = 0;
        std::string sources;
        nlohmann::json rows = nlohmann::json::array();
        for (size_t i = 0; i < variants.size(); ++i) {
            const SiliconMeasurement& m = measured[i];
            const RenderSettings& st = variants[i].settings;
            const size_t scene_index = variant_scene[i];
            const std::string& name = scenes[scene_index];
            const uint32_t w = st.width, h = st.height;
            nlohmann::json row;
            row["scene"] = name;
            row["width"] = w;
            row["height"] = h;
            row["tile"] = st.tile;
            row["spp"] = o->spp;
            row["seed"] = m.seed;
            row["isa"] = isa_name(st.isa);
            row["simd_width"] = isa_width(st.isa);
            row["pinned"] = pinned;
            row["cpu"] = cpu;
            row["predicted.frame_cycles"] = m.predicted_frame;
            row["measured.frame_cycles"] = m.measured_frame;
            row["measured.frame_samples"] = m.frame_samples;
            row["measured.converged"] = m.convergence.converged;
            row["measured.spread"] = m.convergence.spread;
            row["measured.renders"] = m.convergence.samples;
            row["convergence_rule"] = describe(render_rule);
            row["measured.cycle_source"] = m.cycle_source;
            row["measured.cycles_counted"] = m.cycles_counted;
            row["measured.clock_mhz_before"] = m.clock_mhz_before;
            row["measured.clock_mhz_after"] = m.clock_mhz_after;
            row["measured.huge_page_kib_min"] = m.huge_page_kib_min;
            row["measured.huge_page_kib_max"] = m.huge_page_kib_max;
            row["measured.neighbours_busy"] = m.neighbours_busy;
            row["measured.speed_probe_before"] = m.probe_before;
            row["measured.speed_probe_after"] = m.probe_after;
            // The L3: the host file's, and this core's just before the first render, after the
            // last, (memory_now) in the round of the fastest render, the run's, which the model
            // predicted with, and the least and most of the rounds' (kib 0: not chased).
            const HwConfig& described = *variants[i].host;
            if (!described.scene_memory.caches.empty()) {
                row["host.l3_kib"] = described.scene_memory.caches.back().kib;
                row["host.l3_fill_per_us"] =
                    described.scene_memory.caches.back().foreign_fill_per_us;
            }
            row["measured.l3_kib_before"] = m.l3_before.kib;
            row["measured.l3_fill_per_us_before"] = m.l3_before.foreign_fill_per_us;
            row["measured.l3_kib_after"] = m.l3_after.kib;
            row["measured.l3_fill_per_us_after"] = m.l3_after.foreign_fill_per_us;
            row["measured.l3_kib_render"] = m.l3_render.kib;
            row["measured.l3_fill_per_us_render"] = m.l3_render.foreign_fill_per_us;
            row["measured.l3_kib_run"] = m.l3_run.kib;
            row["measured.l3_fill_per_us_run"] = m.l3_run.foreign_fill_per_us;
            row["measured.l3_kib_rounds_min"] = m.l3_rounds_kib_max > 0 ? m.l3_rounds_kib_min : 0;
            row["measured.l3_kib_rounds_max"] = m.l3_rounds_kib_max;
            if (!m.frame_sample_l3_kib.empty()) {
                row["measured.frame_sample_l3_kib"] = m.frame_sample_l3_kib;
                row["measured.frame_sample_l3_fill_per_us"] = m.frame_sample_l3_fill_per_us;
            }
            row["predicted.memory_now"] = o->memory_now;
            row["predicted.frame_cycles_described"] = m.predicted_frame_described;
            row["predicted.frame_cycles_round"] = m.predicted_frame_round;
            if (variants[i].cold) {
                row["predicted.cold_frame_cycles"] = m.predicted_cold_frame;
                row["measured.cold_frame_cycles"] = m.measured_cold_frame;
                row["measured.cold_converged"] = m.cold_convergence.converged;
                row["measured.cold_renders"] = m.cold_convergence.samples;
            }
            row["host.vendor"] = vendor_short_name(uarch.vendor);
            row["host.family"] = uarch.signature.family;
            row["host.model"] = uarch.signature.model;
            row["host.microarchitecture"] = describe(uarch);
            ++workloads;
            converged += m.convergence.converged;
            if (sources.find(m.cycle_source) == std::string::npos)
                sources += (sources.empty() ? "" : "; ") + m.cycle_source;
            row["stage_clock_overhead"] = m.stage_clock_overhead;
            row["measured.interrupted_renders"] = m.interrupted;
            row["measured.clock_moved_renders"] = m.clock_moved;
            row["measured.contended_renders"] = m.contended;
            row["measured.rewarmed_renders"] = m.rewarmed;
            row["measured.render_cycles"] = m.render_cycles;
            row["measured.render_shared_share"] = m.render_shared_share;
            row["measured.monitor_share"] = m.monitor_share;
            row["measured.frame_cycles_parts"] = m.measured_frame_parts;
            row["measured.frame_parts"] = m.frame_parts;
            row["measured.frame_parts_converged"] = m.parts_convergence.converged;
            row["measured.frame_parts_samples"] = m.parts_convergence.samples;
            if (std::isfinite(m.parts_convergence.spread))
                row["measured.frame_parts_spread"] = m.parts_convergence.spread;
            row["measured.frame_tsc"] = m.measured_frame_tsc;
            for (int sg = 0; sg < 3; ++sg) {
                row[std::string("predicted.") + k_stage_names[sg] + "_cycles"] =
                    m.predicted_stage[size_t(sg)];
                row[std::string("predicted.") + k_stage_names[sg] + "_memory_cycles"] =
                    m.predicted_memory[size_t(sg)];
                row[std::string("measured.") + k_stage_names[sg] + "_cycles"] =
                    m.measured_stage[size_t(sg)];
            }
            const char* loops[3] = {"one_ray", "few_ray", "stream"};
            for (int l = 0; l < 3; ++l) {
                row[std::string("predicted.traversal_") + loops[l] + "_loop_cycles"] =
                    m.predicted_loop[size_t(l)];
                row[std::string("measured.traversal_") + loops[l] + "_loop_cycles"] =
                    m.measured_loop[size_t(l)];
                // What the loop's prediction is made of besides its ops' own costs.
                row[std::string("predicted.traversal_") + loops[l] + "_loop_branch_cycles"] =
                    double(m.prediction.timing.traversal_loop_branch_cycles[l]);
                row[std::string("predicted.traversal_") + loops[l] + "_loop_memory_cycles"] =
                    double(m.prediction.timing.traversal_loop_memory_cycles[l]);
                row[std::string("predicted.intersection_") + loops[l] + "_loop_cycles"] =
                    m.predicted_leaf_loop[size_t(l)];
                row[std::string("measured.intersection_") + loops[l] + "_loop_cycles"] =
                    m.measured_leaf_loop[size_t(l)];
            }
            // The shading stage by op kind, and the ray set-up (measured only).
            for (uint32_t k = 0; k < k_op_kind_count; ++k)
                if (m.predicted_shading_op[k] > 0 || m.measured_shading_op[k] > 0) {
                    row[std::string("predicted.op_cycles.") + k_op_kinds[k].name] =
                        m.predicted_shading_op[k];
                    row[std::string("measured.op_cycles.") + k_op_kinds[k].name] =
                        m.measured_shading_op[k];
                }
            row["measured.ray_setup_cycles"] = m.measured_ray_setup;
            std::string making;  // the kinds whose ops make rays, and price their set-up
            for (uint32_t k = 0; k < k_op_kind_count; ++k)
                if (k_op_kinds[k].pushes_rays)
                    making += std::string(making.empty() ? "" : ",") + k_op_kinds[k].name;
            row["ray_making_ops"] = making;
            // The machine model's stall causes and its scene-data misses per level, as sfx
            // simulate reports them (the page sets the frame's error against the misses).
            for (const Stat& stat : m.prediction.stats())
                for (const char* prefix : {"stall_cycles.", "scene_cache.", "scene_memory."})
                    if (stat.name.rfind(prefix, 0) == 0) row["predicted." + stat.name] = stat.value;
            // A batch state's cycles, and its box tests and leaves by loop, as `prefix` + state
            // + "_cycles", "_loop_cycles.LOOP" and "_leaf_loop_cycles.LOOP".
            const auto add_state = [&](const std::string& prefix, const char* state,
                                       const BatchStateCycles& s) {
                row[prefix + state + "_cycles"] = s.cycles;
                for (size_t l = 0; l < 3; ++l) {
                    row[prefix + state + "_loop_cycles." + loops[l]] = s.loops[l];
                    row[prefix + state + "_leaf_loop_cycles." + loops[l]] = s.leaves[l];
                }
            };
            for (const auto& [which, index] :
                 {std::pair<std::string, size_t>{"", scene_index}, {"synthetic.", scenes.size()}})
                for (size_t at = 0; at < predictor[{index, st.isa}].size(); ++at) {
                    const PredictorCheck& c = predictor[{index, st.isa}][at];
                    const PredictorSample& p = c.measured;
                    const std::string kind = which + (p.bounce ? "bounce" : "camera") + ".";
                    const std::string key = "measured.predictor." + kind;
                    if (index == scene_index) {
                        const BranchPredictorConfig& b = variants[i].host->branch_predictor;
                        const PredictorStates& states = modelled_states(c, b.kind);
                        const std::string model = "predicted.predictor." + kind;
                        row[model + "branches"] = states.branches;
                        row[model + "mispredict_cycles"] =
                            b.kind == "none" ? 0.0 : b.mispredict_cycles;
                        row[model + "primed_mispredictions"] = states.primed;
                        row[model + "displaced_mispredictions"] = states.displaced;
                        // Priced as the model prices them: a box test's by its loop, the rest
                        // (the leaf tests') at the pooled cost.
                        std::array<double, 3> box_added{};
                        for (size_t l = 0; l < 3; ++l) {
                            box_added[l] = double(states.displaced_by_loop[l]) -
                                           double(states.primed_by_loop[l]);
                            row[model + "loop_mispredict_cycles." + loops[l]] =
                                b.kind == "none" ? 0.0 : b.mispredict_cycles_in(l);
                        }
                        row[model + "extra_cycles"] =
                            b.kind == "none"
                                ? 0.0
                                : b.price(double(states.displaced) - double(states.primed),
                                          box_added);
                        const BatchMemoryCycles& memory = batch_memory[{index, st.isa}][at];
                        add_state(model, "cold", memory.cold);
                        add_state(model, "warm", memory.warm);
                        add_state(model, "displaced", memory.displaced);
                        for (int l = 0; l < 3; ++l) {
                            const std::string loop = std::string(".") + loops[l];
                            row[model + "primed_loop_mispredictions" + loop] =
                                states.primed_by_loop[size_t(l)];
                            row[model + "displaced_loop_mispredictions" + loop] =
                                states.displaced_by_loop[size_t(l)];
                        }
                    }
                    add_state(key, "primed", p.primed);
                    add_state(key, "cached", p.cached);
                    add_state(key, "displaced", p.displaced);
                    add_state(key, "evicted", p.evicted);
                    row[key + "box_tests"] = p.box_tests;
                    row[key + "lines"] = p.lines;
                    row[key + "batches"] = p.batches;
                    row[key + "converged_batches"] = p.converged_batches;
                }
            rows.push_back(row);
            if (!o->json)
                progress.log(name + " " + std::to_string(w) + "x" + std::to_string(h) + " tile " +
                             std::to_string(st.tile) + " " + isa_name(st.isa) + ": predicted " +
                             std::to_string(m.predicted_frame / 1e6) + " Mcycles, measured " +
                             std::to_string(m.measured_frame / 1e6) +
                             (m.convergence.converged ? "" : " (NOT converged)"));
        }
        progress.finish();
        std::fprintf(stderr, "calibrate --check: %u of %u workloads converged (%s); cycles %s\n",
                     converged, workloads, describe(render_rule).c_str(), sources.c_str());
        std::cout << rows.dump(o->json ? 2 : -1) << "\n";
    });
}

}  // namespace sfx
