#include "sweeps/host_calibration.h"

#include <malloc.h>
#include <sched.h>

#include <algorithm>
#include <boost/math/tools/minima.hpp>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <limits>
#include <map>
#include <memory>
#include <numeric>
#include <random>
#include <sstream>
#include <stdexcept>
#include <thread>

#include "base/cache_eviction.h"
#include "base/convergence.h"
#include "base/core_contention.h"
#include "base/cpu_load.h"
#include "base/cycle_source.h"
#include "base/huge_pages.h"
#include "hw_model/cache_model.h"
#include "hw_model/op_costs.h"
#include "hw_model/ray_buffer_model.h"
#include "hw_model/systemc/systemc_timing.h"
#include "kernels/stream/stream_kernels.h"
#include "kernels/stream/stream_tracer.h"
#include "sweeps/point_group.h"

namespace sfx {

namespace {

// The cost model's traversal record is the native tracer's (hw_model/ray_buffer_model.h).
static_assert(k_traversal_record_bytes == traversal_field::record * sizeof(float));

// Whose per-op cost in a traversal the traversal samples measure: the box test's. A leaf test
// follows a box test nearly always in them, so the two per-op costs cannot be told apart (with
// all three kinds' fitted, three fits on an AMD Zen 5 VM on 2026-11-27 gave the triangle test
// 141, 267 and 178 cycles, the sphere test 0, 190 and 66): the leaf tests' stays the filter
// microbenchmarks'.
bool per_op_from_traversals(OpKind kind) { return kind == OpKind::box_test; }

// Whose one-lane cost the filter microbenchmarks time directly (StreamKernels::leaf_tests of
// one lane runs the one-ray loop's leaf code): the leaf tests'. Fitted on the traversals
// beside the one-lane box test, whose ops come with theirs in fixed ratios, they were not
// determined (on an AMD Zen 5 VM on 2026-11-27 six fits gave the sphere test 4.9-99.9 cycles,
// the triangle test 90-165).
bool one_lane_from_filters(OpKind kind) {
    return kind == OpKind::triangle_test || kind == OpKind::sphere_test;
}

}  // namespace

LanesBeyondCaches lanes_beyond_caches(OpKind kind, uint32_t lanes, uint32_t slots,
                                      const std::vector<HostCacheLevel>& caches,
                                      uint32_t dtlb_pages) {
    const uint32_t lane_bytes =
        lane_page_bytes(stage_of(kind), stream_slot_bytes(), stream_slot_arrays());
    // Without a described L1D, one of 32 KiB.
    const uint32_t l1_kib = caches.empty() ? 32 : caches[0].kib;
    return {beyond_cache_share(lanes, slots, stream_slot_bytes(), lane_bytes, l1_kib),
            caches.size() > 1
                ? beyond_cache_share(lanes, slots, stream_slot_bytes(), lane_bytes, caches[1].kib)
                : 0.0,
            beyond_cache_skipping_share(lanes, slots, stream_slot_bytes(), lane_bytes, l1_kib),
            beyond_tlb_share(lanes, slots, stream_slot_bytes(), lane_bytes, dtlb_pages)};
}

bool microbenchmarks_reach_beyond_l2(const std::vector<uint32_t>& buffer_slots,
                                     const std::vector<HostCacheLevel>& caches) {
    if (caches.size() < 2) return false;
    for (const uint32_t slots : buffer_slots)
        if (beyond_cache_fraction(slots, stream_slot_bytes(), caches[1].kib) > 0) return true;
    return false;
}

std::vector<OneLaneSample> short_stream_fit_samples(const std::vector<OneRaySample>& samples,
                                                    const std::vector<OpCostConfig>& costs,
                                                    uint32_t width,
                                                    const std::vector<HostCacheLevel>& caches,
                                                    const BranchPredictorConfig& predictor,
                                                    uint32_t dtlb_pages) {
    std::array<const OpCostConfig*, k_op_kind_count> cost_of{};
    for (const OpCostConfig& o : costs)
        if (const OpKind kind = op_kind_named(o.op); kind != OpKind::count)
            cost_of[size_t(kind)] = &o;
    std::vector<OneLaneSample> out;
    for (const OneRaySample& s : samples) {
        OneLaneSample sample{s.ops, s.cycles, s.few_ops, 0.0, {}, s.entries};
        sample.traversals = s.streams;
        sample.stream_op_cycles =
            predictor.price(s.modelled_mispredictions, s.modelled_box_loop_mispredictions);
        // The check that a bundle's rays share one origin, at its directly timed cost.
        if (const OpCostConfig* box = cost_of[size_t(OpKind::box_test)])
            sample.stream_op_cycles +=
                double(s.origin_shared_lanes) * box->shared_origin_per_lane_cycles;
        // One-lane leaf tests at their directly timed cost, by outcome.
        for (size_t k = 0; k < k_op_kind_count; ++k)
            if (cost_of[k] && one_lane_from_filters(OpKind(k)) &&
                cost_of[k]->one_lane_cycles >= 0) {
                const OpCostConfig& cost = *cost_of[k];
                sample.leaf_op_cycles +=
                    double(sample.ops[k]) * cost.one_lane_cycles +
                    double(s.one_lane_passed[k]) * cost.one_lane_pass_cycles +
                    double(s.one_lane_failed_candidates[k]) * cost.one_lane_failed_candidate_cycles;
                sample.ops[k] = 0;
            }
        // The stream loop's ops priced by the formula; the box tests' per-op cost left to the
        // fit (a group's cost stays the filter microbenchmarks' throughput: an op's groups are
        // independent).
        for (const OpsOfLength& o : s.stream_ops) {
            const OpCostConfig* cost = cost_of[size_t(o.kind)];
            if (!cost) continue;
            OpCostConfig priced = *cost;
            priced.one_lane_cycles = priced.few_lane_cycles = -1.0;
            if (per_op_from_traversals(o.kind)) {
                priced.per_op_cycles = 0.0;
                sample.stream_ops[size_t(o.kind)] += o.count;
            }
            const LanesBeyondCaches beyond =
                lanes_beyond_caches(o.kind, o.lanes, s.slots, caches, dtlb_pages);
            (o.kind == OpKind::box_test ? sample.stream_op_cycles : sample.leaf_op_cycles) +=
                double(o.count) *
                measured_op_cycles(
                    priced, width, o.lanes,
                    uint32_t(std::lround(double(o.passed) / double(o.count))), beyond.l1, beyond.l2,
                    double(o.failed_candidates) / double(o.count), beyond.l1_skipping, beyond.tlb);
        }
        sample.stream_op_cycles += sample.leaf_op_cycles;
        sample.leaf_cycles_clocked = s.leaf_share * s.cycles;
        for (size_t l = 0; l < 2; ++l) {
            sample.loop_cycles_clocked[l] = s.short_loop_share[l] * s.cycles;
            sample.loop_mispredicted_cycles[l] =
                s.modelled_box_loop_mispredictions[l] * predictor.mispredict_cycles_in(l);
        }
        sample.few_ray_one_lane_box_ops = s.few_ray_one_lane_box_ops;
        out.push_back(sample);
    }
    return out;
}

ShortStreamSplit short_stream_split(const ShortStreamCosts& costs,
                                    const std::vector<OneLaneSample>& fitted,
                                    const std::vector<OneRaySample>& samples,
                                    const BranchPredictorConfig& predictor) {
    if (fitted.size() != samples.size())
        throw std::invalid_argument("short_stream_split: the fit's samples are not the batches'");
    constexpr size_t box = size_t(OpKind::box_test);
    ShortStreamSplit split;
    for (size_t i = 0; i < samples.size(); ++i) {
        const OneRaySample& s = samples[i];
        const OneLaneSample& f = fitted[i];
        // A one-lane box test below a few-ray stream is the few-ray loop's (the clock's split;
        // priced at the one-lane cost either way). Until 2026-12-05 the split put them in the
        // one-ray loop: on an AMD Zen 5 VM (AVX2) it read the one-ray loop priced 3.9 times
        // over and the few-ray loop 22 % under, where the two together were priced right.
        const double nested = few_ray_one_lane_box_tests(f);
        const double one_ray =
            (double(f.ops[box]) - nested) * costs.one_lane[box] +
            double(f.entries[0]) * costs.entry[0] +
            s.modelled_box_loop_mispredictions[0] * predictor.mispredict_cycles_in(0);
        const double few_ray =
            double(f.few_ops[box]) * costs.few_lane[box] + nested * costs.one_lane[box] +
            double(f.entries[1]) * costs.entry[1] +
            s.modelled_box_loop_mispredictions[1] * predictor.mispredict_cycles_in(1);
        split.one_ray.priced += one_ray;
        split.few_ray.priced += few_ray;
        split.leaves.priced += f.leaf_op_cycles;
        split.rest.priced += short_stream_cycles(costs, f) - one_ray - few_ray - f.leaf_op_cycles;
        const double one_ray_measured = s.short_loop_share[0] * s.cycles,
                     few_ray_measured = s.short_loop_share[1] * s.cycles,
                     leaves_measured = s.leaf_share * s.cycles;
        split.one_ray.measured += one_ray_measured;
        split.few_ray.measured += few_ray_measured;
        split.leaves.measured += leaves_measured;
        split.rest.measured += s.cycles - one_ray_measured - few_ray_measured - leaves_measured;
    }
    return split;
}

ModelledMispredictions replay_short_stream_predictor(const TraversalRecorder& others,
                                                     const TraversalRecorder& batch, uint32_t width,
                                                     const std::vector<uint8_t>& node_leaf,
                                                     const std::string& predictor_kind) {
    PassBuffer batch_trace;
    batch(batch_trace);
    ModelledMispredictions m;
    // The unseen-ops predictor mispredicts none: the batch was just run (the others' recording
    // ends with it).
    if (predictor_kind != "unseen_ops") {
        PassBuffer others_trace;
        others(others_trace);
        std::array<uint64_t, 3> by_loop{};
        m.total =
            double(simulate_displaced_batch(others_trace, batch_trace, width, node_leaf, &by_loop));
        for (size_t l = 0; l < 3; ++l) m.box_by_loop[l] = double(by_loop[l]);
    }
    const std::vector<TraversalLoop> loops = traversal_loops(batch_trace, width);
    for (uint32_t i = 0; i < batch_trace.size(); ++i)
        m.few_ray_one_lane_box_ops += batch_trace.at(i).kind == OpKind::box_test &&
                                      batch_trace.at(i).length == 1 &&
                                      loops[i] == TraversalLoop::few_ray;
    return m;
}

void set_short_stream_costs(const ShortStreamCosts& fit, std::vector<OpCostConfig>& costs) {
    for (OpCostConfig& o : costs) {
        const OpKind kind = op_kind_named(o.op);
        if (kind == OpKind::count) continue;
        // A fitted 0 is a cost; a term no sample had is not measured (negative).
        if (!one_lane_from_filters(kind) || o.one_lane_cycles < 0)
            o.one_lane_cycles =
                fit.one_lane_measured[size_t(kind)] ? fit.one_lane[size_t(kind)] : -1.0;
        o.few_lane_cycles = fit.few_lane_measured[size_t(kind)] ? fit.few_lane[size_t(kind)] : -1.0;
        if (fit.stream_measured[size_t(kind)]) o.per_op_cycles = fit.stream_per_op[size_t(kind)];
        if (kind == OpKind::box_test) {
            o.one_ray_entry_cycles = fit.entry[0];
            o.few_ray_entry_cycles = fit.entry[1];
            o.traversal_start_cycles = fit.traversal_start;
        }
    }
}

std::array<double, 3> fit_loop_mispredict_cycles(const std::vector<PredictorCheck>& samples) {
    std::array<double, 3> cycles{}, mispredictions{};
    double all = 0.0;
    for (const PredictorCheck& b : samples)
        for (size_t l = 0; l < 3; ++l) {
            cycles[l] += b.measured.displaced.loops[l] - b.measured.cached.loops[l];
            mispredictions[l] +=
                double(b.modelled.displaced_by_loop[l]) - double(b.modelled.primed_by_loop[l]);
        }
    for (double m : mispredictions) all += std::max(0.0, m);
    std::array<double, 3> cost{-1.0, -1.0, -1.0};
    for (size_t l = 0; l < 3; ++l)
        if (all > 0 && mispredictions[l] >= k_loop_mispredict_min_share * all)
            cost[l] = fit_mispredict_cycles({cycles[l]}, {mispredictions[l]});
    return cost;
}

const PredictorStates& modelled_states(const PredictorCheck& check, const std::string& kind) {
    return kind == "unseen_ops" ? check.unseen : check.modelled;
}

UnseenOpCosts fit_unseen_op_cycles(const std::vector<PredictorCheck>& samples) {
    std::array<double, 3> cycles{}, ops{};
    double leaf_cycles = 0.0, leaf_ops = 0.0;
    for (const PredictorCheck& b : samples) {
        double in_loops = 0.0, box_ops = 0.0;
        for (size_t l = 0; l < 3; ++l) {
            const double extra = b.measured.displaced.loops[l] - b.measured.cached.loops[l];
            cycles[l] += extra;
            in_loops += extra;
            ops[l] += double(b.unseen.displaced_by_loop[l]);
            box_ops += double(b.unseen.displaced_by_loop[l]);
        }
        leaf_cycles += b.measured.displaced.cycles - b.measured.cached.cycles - in_loops;
        leaf_ops += double(b.unseen.displaced) - box_ops;
    }
    UnseenOpCosts out;
    for (size_t l = 0; l < 3; ++l)
        if (ops[l] > 0) out.box_by_loop[l] = std::max(0.0, cycles[l] / ops[l]);
    out.leaf = leaf_ops > 0 ? std::max(0.0, leaf_cycles / leaf_ops) : 0.0;
    return out;
}

std::vector<PredictorCheck> check_predictor(const Scene& scene, const Bvh& bvh, Isa isa,
                                            const ConvergenceRule& convergence, bool time_evicted) {
    std::vector<std::shared_ptr<PassBuffer>> batches[2];  // camera rays, bounces
    const std::vector<PredictorSample> measured = run_predictor_microbenchmarks(
        scene, bvh, isa, convergence, 3,
        [&](bool bounce, uint32_t) {
            batches[bounce].push_back(std::make_shared<PassBuffer>());
            return batches[bounce].back().get();
        },
        time_evicted);
    RenderSettings settings;
    settings.tile = 128;  // the batches' slots span both kinds' rays (2 x 64 x 64)
    const WorkloadShape shape = workload_shape(scene, bvh, settings);
    std::vector<PredictorCheck> out;
    for (const PredictorSample& m : measured) {
        std::vector<const PassBuffer*> kind;
        for (const auto& b : batches[m.bounce]) kind.push_back(b.get());
        PredictorCheck c{
            m,
            simulate_predictor_states(kind, isa_width(resolve_isa(isa)), *shape.node_leaf),
            unseen_ops_states(kind, isa_width(resolve_isa(isa))),
            {},
            shape};
        c.batches.assign(batches[m.bounce].begin(), batches[m.bounce].end());
        out.push_back(std::move(c));
    }
    return out;
}

BatchMemoryCycles model_batch_memory(const HwConfig& host, const PredictorCheck& sample,
                                     bool after_others) {
    HwConfig config = host;
    config.branch_predictor.kind = "none";
    BatchMemoryCycles out;
    // Times `batch` on `timing`, adding its cycles, and each loop's box tests and leaves, to
    // `sums`.
    const auto run = [](SystemcTiming& timing, const PassBuffer& batch, BatchStateCycles& sums) {
        const FrameTiming before = timing.timing(0);
        timing.begin_pass(batch.pass());
        for (size_t i = 0; i < batch.size(); ++i) timing.op(batch.at(i));
        timing.end_pass(batch.pass());
        const FrameTiming t = timing.timing(0);
        sums.cycles += double(t.cycles - before.cycles);
        for (size_t l = 0; l < 3; ++l) {
            sums.loops[l] += double(t.traversal_loop_cycles[l] - before.traversal_loop_cycles[l]);
            sums.leaves[l] +=
                double(t.intersection_loop_cycles[l] - before.intersection_loop_cycles[l]);
        }
    };
    for (const auto& batch : sample.batches) {
        {
            SystemcTiming timing({config}, sample.shape);
            run(timing, *batch, out.cold);
            run(timing, *batch, out.warm);
        }  // one SystemcTiming at a time: SystemC has one simulation context
        if (!after_others) continue;
        SystemcTiming displaced({config}, sample.shape);
        BatchStateCycles before;  // the runs that set the state up, not summed
        run(displaced, *batch, before);
        for (const auto& other : sample.batches)
            if (other != batch) run(displaced, *other, before);
        run(displaced, *batch, out.displaced);
    }
    return out;
}

NodeReadFit fit_node_read_exposed_share(const HwConfig& host,
                                        const std::vector<PredictorCheck>& samples,
                                        const std::vector<PredictorSample>& baseline,
                                        const double* given_share) {
    if (samples.empty()) throw std::invalid_argument("no branch microbenchmark samples to fit");
    const auto short_loops = [](const std::array<double, 3>& loops) {
        return loops[size_t(TraversalLoop::one_ray)] + loops[size_t(TraversalLoop::few_ray)];
    };
    const auto modeled = [&](double share) {
        HwConfig config = host;
        for (OpCostConfig& cost : config.op_costs)
            if (op_kind_named(cost.op) == OpKind::box_test) cost.node_read_exposed_share = share;
        std::vector<double> out;
        for (const PredictorCheck& s : samples) {
            const BatchMemoryCycles m = model_batch_memory(config, s);
            out.push_back(short_loops(m.cold.loops) - short_loops(m.warm.loops));
        }
        return out;
    };
    NodeReadFit fit;
    for (const PredictorCheck& check : samples) {
        const PredictorSample& s = check.measured;
        double extra = short_loops(s.evicted.loops) - short_loops(s.primed.loops);
        for (const PredictorSample& b : baseline)
            if (b.bounce == s.bounce)
                extra -= short_loops(b.evicted.loops) - short_loops(b.primed.loops);
        fit.measured.push_back(extra);
    }
    // The model's extra is not proportional to the share (a shorter wait for a node can leave
    // the core waiting on something else, as a node whose address is in its parent's data), but
    // it does not fall as the share grows: Brent's search finds the least squared error.
    const auto error_of = [&](const std::vector<double>& m) {
        double sum = 0.0;
        for (size_t i = 0; i < m.size(); ++i)
            sum += (m[i] - fit.measured[i]) * (m[i] - fit.measured[i]);
        return sum;
    };
    const double best = boost::math::tools::brent_find_minima(
                            [&](double share) { return error_of(modeled(share)); }, 0.0, 1.0, 10)
                            .first;
    fit.modeled_whole = modeled(1.0);
    // The search's ends are candidates too, and win a tie.
    fit.share = best;
    fit.modeled = modeled(fit.share);
    for (const double end : {0.0, 1.0}) {
        std::vector<double> m = end == 1.0 ? fit.modeled_whole : modeled(end);
        if (error_of(m) <= error_of(fit.modeled)) fit.share = end, fit.modeled = std::move(m);
    }
    fit.own_share = fit.share;
    if (given_share) {
        fit.given = true;
        fit.share = *given_share;
        fit.modeled = modeled(fit.share);
    }
    std::vector<double> errors;
    for (size_t i = 0; i < samples.size(); ++i)
        errors.push_back(std::abs(fit.modeled[i] - fit.measured[i]) /
                         std::max(std::abs(fit.measured[i]), 1.0));
    std::sort(errors.begin(), errors.end());
    fit.error = {errors[errors.size() / 2], errors.back()};
    return fit;
}

FewRayFrom few_ray_costs_from(const HwConfig& file, const std::string& source, Isa isa) {
    const Isa resolved = resolve_isa(isa);
    if (isa_width(resolved) < k_few_ray_min_width)
        throw std::invalid_argument("the " + std::string(isa_name(resolved)) +
                                    " back end has no few-ray loop (" +
                                    std::to_string(k_few_ray_min_width) + " lanes or more)");
    for (const OpCostConfig& o : file.op_costs)
        if (op_kind_named(o.op) == OpKind::box_test && o.few_lane_cycles >= 0 &&
            file.branch_predictor.kind != "none")
            return {{o.few_lane_cycles, o.few_ray_entry_cycles},
                    file.branch_predictor.mispredict_cycles_in(1),
                    file.branch_predictor.kind,
                    o.node_read_exposed_share,
                    source};
    throw std::invalid_argument(
        "no few-ray loop costs (the box test's few_lane_cycles and a fitted branch_predictor: a "
        "back end of " +
        std::to_string(k_few_ray_min_width) + " lanes or more writes them)");
}

std::vector<double> fit_residuals_by(const OpCostConfig& cost, uint32_t width,
                                     const std::vector<OpCostSample>& samples,
                                     const std::vector<uint32_t>& keys,
                                     const std::vector<uint32_t>& wanted) {
    std::vector<double> medians;
    for (const uint32_t key : wanted) {
        std::vector<double> errors;
        for (size_t i = 0; i < samples.size(); ++i) {
            if (keys[i] != key) continue;
            const OpCostSample& s = samples[i];
            const double priced =
                measured_op_cycles(cost, width, s.lanes, s.passed, s.beyond_l1, s.beyond_l2,
                                   s.failed_candidates, s.beyond_l1_skipping, s.beyond_tlb);
            // A measurement under the clock's steps counts as those, as in fit_error.
            errors.push_back((priced - s.cycles) / std::max(s.cycles, k_fit_resolution_cycles));
        }
        medians.push_back(errors.empty() ? std::nan("") : median(errors));
    }
    return medians;
}

HostCalibration calibrate_host(Isa isa, const ConvergenceRule& convergence,
                               const std::function<void(uint32_t, uint32_t)>& progress,
                               const HwConfig* memory_from, const std::string& memory_source,
                               const FewRayFrom* few_ray_from, const std::string& branch_model) {
    HostCalibration c;
    const Isa resolved = resolve_isa(isa);
    c.host = describe_host(isa_width(resolved), describe_isa(resolved), memory_from == nullptr);
    if (memory_from) {
        c.host.memory = memory_from->scene_memory;
        c.host.memory_source = memory_source;
    }
    c.host.slot_bytes = stream_slot_bytes();
    c.host.slot_arrays = stream_slot_arrays();
    c.speed_probe_start_cycles = speed_probe_cycles(resolved, convergence);
    MicrobenchOptions options;
    options.isa = resolved;
    options.convergence = convergence;
    c.samples = run_stream_microbenchmarks(options, progress);
    c.microbench_visits = options.visits;
    c.sweep_probe_points_cycles = speed_probe_points_cycles(c.samples);
    c.rates = run_gather_compress_microbenchmarks(resolved, convergence.budget);
    for (const MicrobenchSample& s : c.samples) c.converged_points += s.converged;
    c.points = uint32_t(c.samples.size());
    c.residual_buffer_slots = options.buffer_slots;
    c.residual_lengths = options.lengths;
    const uint32_t slot_bytes = stream_slot_bytes();
    std::map<OpKind, std::vector<OpCostSample>> by_kind;
    std::map<OpKind, std::vector<uint32_t>> slots_of;      // by_kind's samples' buffers
    std::map<OpKind, std::vector<OpCostSample>> one_lane;  // a leaf test's one-lane samples
    std::vector<OpCostSample> lens_camera;           // the camera's on a thin lens
    std::vector<OpCostSample> sphere_light;          // the direct-light filter's on a sphere
    std::vector<OpCostSample> failing_candidates;    // the triangle test's
    std::vector<OpCostSample> sphere_hits;           // the emission filter's on sphere hits
    std::map<OpKind, std::vector<double>> cold_calls;  // a shading op's, one a length
    for (const MicrobenchSample& s : c.samples) {
        if (s.cold_call_timed) cold_calls[s.kind].push_back(s.cold_call_cycles);
        if (s.lanes == 1 && one_lane_from_filters(s.kind)) {
            one_lane[s.kind].push_back({1, s.passed, 0.0, s.cycles, s.failed_candidates});
            continue;
        }
        const LanesBeyondCaches beyond =
            lanes_beyond_caches(s.kind, s.lanes, s.slots, c.host.caches, c.host.dtlb.pages);
        const OpCostSample sample{
            s.lanes,   s.passed,           beyond.l1, s.cycles, s.failed_candidates,
            beyond.l2, beyond.l1_skipping, beyond.tlb};
        std::vector<OpCostSample>* variant = s.thin_lens            ? &lens_camera
                                             : s.sphere_light       ? &sphere_light
                                             : s.failing_candidates ? &failing_candidates
                                             : s.sphere_hits        ? &sphere_hits
                                                                    : nullptr;
        if (variant) {
            variant->push_back(sample);
            continue;
        }
        by_kind[s.kind].push_back(sample);
        slots_of[s.kind].push_back(s.slots);
    }
    size_t points = 0;
    const uint32_t largest_buffer =
        options.buffer_slots.empty()
            ? 0
            : *std::max_element(options.buffer_slots.begin(), options.buffer_slots.end());
    for (const auto& [kind, samples] : by_kind) {
        c.op_costs.push_back(fit_op_cost(to_string(kind), c.host.simd_width, samples));
        fit_one_lane_by_outcome(c.op_costs.back(), one_lane[kind]);
        if (kind == OpKind::camera) {
            c.op_costs.back().thin_lens_per_lane_cycles =
                fit_extra_per_passing_lane(c.op_costs.back(), c.host.simd_width, lens_camera);
            points += lens_camera.size();
        }
        if (kind == OpKind::lambertian_direct) {
            c.op_costs.back().sphere_light_per_pass_cycles =
                fit_extra_per_passing_lane(c.op_costs.back(), c.host.simd_width, sphere_light);
            points += sphere_light.size();
        }
        if (kind == OpKind::triangle_test) {
            c.op_costs.back().per_failed_candidate_cycles = fit_extra_per_failed_candidate(
                c.op_costs.back(), c.host.simd_width, failing_candidates);
            points += failing_candidates.size();
        }
        if (kind == OpKind::emission_filter) {
            c.op_costs.back().sphere_hit_per_lane_cycles =
                fit_extra_per_lane(c.op_costs.back(), c.host.simd_width, sphere_hits);
            points += sphere_hits.size();
        }
        c.op_costs.back().cold_call_cycles = fit_cold_call_cycles(cold_calls[kind]);
        c.fit_errors.push_back(fit_error(c.op_costs.back(), c.host.simd_width, samples));
        c.residuals_by_buffer.push_back(fit_residuals_by(
            c.op_costs.back(), c.host.simd_width, samples, slots_of[kind], options.buffer_slots));
        std::vector<uint32_t> lanes_at_largest;  // 0: at another buffer
        for (size_t i = 0; i < samples.size(); ++i)
            lanes_at_largest.push_back(slots_of[kind][i] == largest_buffer ? samples[i].lanes : 0);
        c.residuals_by_length.push_back(fit_residuals_by(
            c.op_costs.back(), c.host.simd_width, samples, lanes_at_largest, options.lengths));
        points += samples.size() + one_lane[kind].size();
    }
    // The cost of a misprediction of the model's branch predictor: on a scene of random
    // triangles, what the displaced batches took beyond the cached ones, over the
    // mispredictions the model adds from primed to displaced on the same batches (the TAGE's;
    // the unseen-ops predictor's: each traversal op of a displaced batch, fit_unseen_op_cycles).
    const Scene branch_scene = branch_microbench_scene();
    c.branch_samples = check_predictor(branch_scene, Bvh(branch_scene), resolved, convergence);
    std::vector<double> extra_cycles, extra_mispredictions;
    for (const PredictorCheck& b : c.branch_samples) {
        const PredictorStates& m = modelled_states(b, branch_model);
        extra_cycles.push_back(b.measured.displaced.cycles - b.measured.cached.cycles);
        extra_mispredictions.push_back(double(m.displaced) - double(m.primed));
        c.converged_points += b.measured.converged_batches;
        c.points += b.measured.batches;
    }
    c.host.branch_predictor.kind = branch_model;
    std::array<double, 3> by_loop{};
    if (branch_model == "unseen_ops") {
        const UnseenOpCosts unseen = fit_unseen_op_cycles(c.branch_samples);
        c.host.branch_predictor.mispredict_cycles = unseen.leaf;
        by_loop = unseen.box_by_loop;
    } else {
        c.host.branch_predictor.mispredict_cycles =
            fit_mispredict_cycles(extra_cycles, extra_mispredictions);
        by_loop = fit_loop_mispredict_cycles(c.branch_samples);
    }
    c.host.branch_predictor.one_ray_mispredict_cycles = by_loop[0];
    c.host.branch_predictor.few_ray_mispredict_cycles =
        few_ray_from ? few_ray_from->mispredict_cycles : by_loop[1];
    if (few_ray_from) c.host.few_ray_source = few_ray_from->source;
    c.host.branch_predictor.stream_mispredict_cycles = by_loop[2];
    std::ostringstream branch_note;
    branch_note << "the branch microbenchmark (kernels/stream/stream_microbench.h: 20,000 random "
                << "triangles, a 64 x 64 frame's 16 x 16 tile batches, camera rays and bounces):";
    for (size_t k = 0; k < c.branch_samples.size(); ++k)
        branch_note << (k ? ";" : "") << " "
                    << (c.branch_samples[k].measured.bounce ? "bounces" : "camera rays")
                    << " displaced over cached " << std::llround(extra_cycles[k]) << " cycles, "
                    << std::llround(extra_mispredictions[k])
                    << (branch_model == "unseen_ops" ? " traversal ops" : " mispredictions added");
    branch_note << (branch_model == "unseen_ops"
                        ? " (a box test's cost by the loop that runs it, the stage clock's split; "
                          "a leaf test's outside the loops)"
                        : " (the model's predictor, primed to displaced)")
                << "; no frame";
    c.host.branch_predictor_fit = branch_note.str();
    // What evicting costs the synthetic scene's batches, whose scene is a few lines: the code,
    // TLB and page tables a read of 256 MiB evicts besides the scene (fit_node_read_exposed_share).
    c.eviction_baseline = run_predictor_microbenchmarks(resolved, convergence);
    for (const PredictorSample& b : c.eviction_baseline) {
        c.converged_points += b.converged_batches;
        c.points += b.batches;
    }
    // Ops of one lane run in the one-ray loop, and a wide back end's box tests of a few lanes in
    // the few-ray loop, not the filters above: their own fit, of what the samples' other ops
    // (their leaves' tests) and the model's mispredictions on them (priced above) leave when
    // the formula above prices them. Those mispredictions are in the samples' cycles, and the
    // model adds its own to every traversal: fitted into the costs, a frame paid them twice
    // (atrium 64 x 64, AVX-512, tile 32, on an Intel Xeon VM, 2026-11-28: 20.9 M cycles
    // predicted, 17.0 measured, 4.4 M of them the predictor's).
    // The tracer's check that a traversal's rays share one origin, per lane, timed by itself
    // (priced in the traversals below, as a frame's camera rays pay it).
    c.shared_origin = run_shared_origin_microbenchmark(resolved, convergence);
    c.converged_points += c.shared_origin.converged;
    ++c.points;
    for (OpCostConfig& o : c.op_costs)
        if (op_kind_named(o.op) == OpKind::box_test)
            o.shared_origin_per_lane_cycles = c.shared_origin.per_lane_cycles;
    // A traversal's start cold, as a frame's (its box test that starts it carries it).
    c.cold_traversal_cycles = run_cold_traversal_microbenchmarks(resolved, c.cold_traversal_lengths,
                                                                 options.cold_call_pairs);
    for (OpCostConfig& o : c.op_costs)
        if (op_kind_named(o.op) == OpKind::box_test)
            o.cold_call_cycles = fit_cold_call_cycles(c.cold_traversal_cycles);
    const std::vector<uint8_t> one_ray_leaves = bvh_leaves(Bvh(one_ray_microbench_scene()));
    c.one_ray_samples = run_one_ray_microbenchmarks(
        resolved, convergence, 1,
        [&](const TraversalRecorder& others, const TraversalRecorder& batch) {
            return replay_short_stream_predictor(others, batch, c.host.simd_width, one_ray_leaves,
                                                 branch_model);
        });
    for (const OneRaySample& s : c.one_ray_samples) c.converged_points += s.converged;
    c.points += uint32_t(c.one_ray_samples.size());
    c.short_stream_samples =
        short_stream_fit_samples(c.one_ray_samples, c.op_costs, c.host.simd_width, c.host.caches,
                                 c.host.branch_predictor, c.host.dtlb.pages);
    c.short_stream_costs = fit_short_stream_cycles(c.short_stream_samples,
                                                   few_ray_from ? &few_ray_from->costs : nullptr);
    c.short_stream_fit_errors =
        short_stream_fit_error(c.short_stream_costs, c.short_stream_samples);
    c.filter_costs = c.op_costs;
    set_short_stream_costs(c.short_stream_costs, c.op_costs);
    // The hits' surfaces read beyond the caches: the share of the cache model's latency the
    // core leaves exposed, for the op that reads them (the emission filter).
    c.surface_read_samples = run_surface_read_microbenchmarks(resolved, convergence);
    std::vector<HitReadSample> hit_reads;
    for (const SurfaceReadSample& s : c.surface_read_samples) {
        // Replayed: the third repetition's hits after the first two's, which warmed the caches
        // as the repetitions before any measured one did (which repetition was fastest is not
        // kept; every repetition draws its hits alike).
        HitReadSample h;
        h.triangles = s.triangles;
        for (uint32_t rep = 0; rep + 1 < std::min(s.repetitions, 3u); ++rep) {
            const std::vector<uint32_t> prims = surface_read_hits(s, rep);
            h.warm_prims.insert(h.warm_prims.end(), prims.begin(), prims.end());
        }
        h.timed_prims = surface_read_hits(s, std::min(s.repetitions, 3u) - 1);
        h.extra_cycles = s.cycles - s.resident_cycles;
        hit_reads.push_back(std::move(h));
        c.converged_points += s.converged;
    }
    c.points += uint32_t(c.surface_read_samples.size());
    c.host.speed_probe_cycles = speed_probe_cycles(resolved, convergence);
    const HwConfig host_config = host_hw_config(c.host, c.op_costs);
    c.hit_read_fit = fit_hit_read_exposed_share(host_config, hit_reads);
    for (OpCostConfig& cost : c.op_costs) {
        const OpKind kind = op_kind_named(cost.op);
        if (kind != OpKind::count && op_info(kind).reads_hit_primitive)
            cost.hit_read_exposed_share = c.hit_read_fit.share;
    }
    // The short loops' exposed share of a node read: the branch microbenchmark's batches from
    // DRAM, less what evicting costs the synthetic scene's, through the model at these costs.
    // A wide back end takes the share with the few-ray loop's costs: the one-ray and few-ray
    // loops are the same code at 8 and 16 lanes (on the Intel Xeon VM, 2026-12-06, fitted
    // apart the two back ends read 0.621 and 1.000, the latter at its bound with its two
    // batches' errors of opposite sign, and the width ranking followed the difference).
    c.node_read_fit = fit_node_read_exposed_share(
        host_config, c.branch_samples, c.eviction_baseline,
        few_ray_from ? &few_ray_from->node_read_exposed_share : nullptr);
    for (OpCostConfig& cost : c.op_costs)
        if (op_kind_named(cost.op) == OpKind::box_test)
            cost.node_read_exposed_share = c.node_read_fit.share;
    auto three_places = [](double v) {
        char text[32];
        std::snprintf(text, sizeof text, "%.3f", v);
        return std::string(text);
    };
    auto slash_joined = [](const std::vector<uint32_t>& values) {
        std::string joined;
        for (const uint32_t v : values) joined += (joined.empty() ? "" : "/") + std::to_string(v);
        return joined;
    };
    std::ostringstream note;
    note << points << " microbenchmark points of the native filters on synthetic streams ("
         << describe_isa(resolved) << "; stream lengths 1-4096, ids scattered over buffers of "
         << slash_joined(options.buffer_slots) << " slots of " << slot_bytes << " bytes"
         << " in increasing order, which tells a lane beyond the L1D that opens a page of its "
            "array from one that skips lines in a page the lane before opened, and from one on "
            "the next line";
    if (c.host.caches.size() >= 2 &&
        !microbenchmarks_reach_beyond_l2(options.buffer_slots, c.host.caches))
        note << ", none of them beyond this host's L2 (" << c.host.caches[1].kib
             << " KiB): beyond_l2_per_lane_cycles is 0, not measured, and a tile whose rays "
                "outgrow the L2 is priced as if it held them";
    note << " (a shading op's and a leaf "
         << "test's streams also with every lane passing and with none, for a passing lane's "
         << "and a minority lane's costs; the "
         << "filters a frame runs after the miss and shadow filters dealt only hits of rays "
         << "that are not shadow rays; the material filter timed as the sort by material "
         << "the tracer runs for a generation's material filters), the "
         << "triangle and sphere tests through the traversal's leaf code, the fastest of "
         << "repetitions "
         << "until " << describe(convergence) << " in each of " << options.visits
         << " sweeps over the points, judged over all (" << c.converged_points << " of " << c.points
         << " points converged; kernels/stream/stream_microbench.h), least squares on relative "
         << "error; a shading op's cold call (after a pass of a 16 x 16 tile) over a warm one, "
         << "the mean over " << options.cold_call_pairs << " pairs of single calls at each of "
         << "its mixed points of " << options.cold_call_slots << " slots and "
         << slash_joined(options.cold_call_lengths)
         << " lanes, the median over the lengths, and a traversal's start likewise on streams of "
         << slash_joined(c.cold_traversal_lengths) << " rays; "
         << "the triangle and sphere tests' one-lane costs by the lane's outcome, the "
         << "medians of their one-lane points that fail, pass and (the triangle test's) fail as "
         << "candidates (the one-ray loop's leaf code); one-lane and (" << k_few_ray_min_width
         << "+ lanes) few-lane box "
         << "costs, the one-ray and few-ray loops' entry costs, a traversal's start and the "
         << "stream loop's per-op box cost, from " << c.one_ray_samples.size()
         << " batches of traversals"
         << (few_ray_from ? " (the few-ray loop's box and entry costs as " + few_ray_from->source +
                                " gives them: the same code at 8 and 16 lanes)"
                          : std::string())
         << " (8-32 streams of one ray and 4-32 of 2 to " << k_few_ray_lanes
         << " rays from the root, 8 and 32 entering 3 and 6 levels down, 1 and 4 of 8 to 128) "
         << "of the same scene, other rays' traversals between repetitions, each loop against "
         << "its part by the stage clock's split (their leaf tests taken off by it), less the "
            "model's "
         << "mispredictions on them at mispredict_cycles (the model adds its own to every "
         << "traversal); the hit reads' "
         << "exposed "
         << "share of the latency beyond an L2 hit (which the loop's prefetches cover) from "
         << c.surface_read_samples.size()
         << " streams of 4096 hits on meshes of 416 KiB-52 MiB against a resident one, "
         << "through the cache model (relative error median "
         << std::lround(100 * c.hit_read_fit.error.first) << " %, worst "
         << std::lround(100 * c.hit_read_fit.error.second) << " %); the box test's exposed "
         << "share of a node read's latency in the one-ray and few-ray loops "
         << (few_ray_from ? "as " + few_ray_from->source +
                                " gives it (the same code at 8 and 16 lanes), judged on "
                          : std::string("from "))
         << "the branch microbenchmark's batches from DRAM over primed in those loops, less the "
         << "synthetic scene's, through the model (relative error median "
         << std::lround(100 * c.node_read_fit.error.first) << " %, worst "
         << std::lround(100 * c.node_read_fit.error.second) << " %"
         << (few_ray_from ? "; these batches alone fit " + three_places(c.node_read_fit.own_share)
                          : std::string())
         << "); no frame";
    c.yaml = host_hw_yaml(c.host, c.op_costs, note.str());
    return c;
}

bool pin_to_current_cpu() {
    const int cpu = sched_getcpu();
    if (cpu < 0) return false;
    cpu_set_t set;
    CPU_ZERO(&set);
    CPU_SET(cpu, &set);
    return sched_setaffinity(0, sizeof set, &set) == 0;
}

namespace {

// How often the contention monitor probes a render (ContentionMonitor): every millisecond.
constexpr double k_monitor_period_us = 1000.0;

// The machine model's prediction of one workload, through the path sfx simulate takes.
void predict(const Scene& scene, const Bvh& bvh, RenderSettings settings, const HwConfig& host,
             bool cold, SiliconMeasurement& m) {
    settings.stage_clock = false;
    // Every measured render follows two renders of its own workload, its other frames 2 and 1
    // (predict_and_measure), so the prediction starts from the caches those leave, not from
    // empty ones: two frames of other seeds touch more of a large scene than one (warmed by one,
    // the model put atrium's and conference's AVX2 frames 1-12 % dearer than warmed by their
    // own frame, by two 1-9 %).
    SamplingOptions warm;
    warm.warm_frames = uint32_t(k_warm_frame);
    const PointGroupResult r = run_point_group(scene, bvh, settings, {host}, Fidelity::full, warm);
    m.prediction = r.predictions.front();
    const FrameTiming& t = m.prediction.timing;
    for (int s = 0; s < 3; ++s)
        for (int secondary = 0; secondary < 2; ++secondary) {
            const StageTiming& st = t.stages[secondary][s];
            m.predicted_stage[size_t(s)] += double(st.busy_cycles + st.stall_cycles);
            m.predicted_memory[size_t(s)] += double(st.scene_memory_cycles);
        }
    for (int l = 0; l < 3; ++l) m.predicted_loop[size_t(l)] = double(t.traversal_loop_cycles[l]);
    for (int l = 0; l < 3; ++l)
        m.predicted_leaf_loop[size_t(l)] = double(t.intersection_loop_cycles[l]);
    for (uint32_t k = 0; k < k_op_kind_count; ++k)
        if (stage_of(OpKind(k)) == OpStage::shading)
            m.predicted_shading_op[k] = double(t.op_cycles[k]);
    m.predicted_frame = double(t.cycles);
    if (cold)  // from empty caches, as the renders after evict_caches start (their frame)
        m.predicted_cold_frame =
            double(run_point_group(scene, bvh, other_frame(settings, k_cold_frame), {host},
                                   Fidelity::full, SamplingOptions{})
                       .predictions.front()
                       .timing.cycles);
}

// One render, trace off, with or without the stage clock: its core cycles from `source`
// (counted, or the thread's CPU time at the back end's clock measured before and after) and
// its TSC ticks. The TSC counts while the thread is descheduled too, and on a shared machine
// that is often most of a render's wall time; a render whose TSC ticks exceed its CPU time at
// the TSC rate by more than 3 % is counted as interrupted.
std::pair<CycleReading, double> timed_render(const Scene& scene, const Bvh& bvh,
                                             RenderSettings settings, bool clock,
                                             CycleSource& source, double tsc_mhz,
                                             RenderResult& result, uint32_t& interrupted) {
    settings.stage_clock = clock;
    settings.part_clock = !clock;
    source.start();
    const uint64_t start = read_tsc();
    result = render_stream(scene, bvh, settings);
    const double ticks = double(read_tsc() - start);
    const CycleReading r = source.stop();
    if (ticks > 1.03 * r.cpu_seconds * 1e6 * tsc_mhz + 2000.0) ++interrupted;
    return {r, ticks};
}

}  // namespace

namespace {

// The speed probe's microbenchmark points (speed_probe_cycles).
MicrobenchOptions speed_probe_options(Isa isa, const ConvergenceRule& convergence) {
    MicrobenchOptions options;
    options.isa = isa;
    options.convergence = convergence;
    options.kinds = {OpKind::box_test, OpKind::triangle_test, OpKind::emission_filter,
                     OpKind::lambertian_indirect};
    options.buffer_slots = {1024};
    options.lengths = {512, 1024};
    return options;
}

}  // namespace

double speed_probe_points_cycles(const std::vector<MicrobenchSample>& samples) {
    const MicrobenchOptions probe = speed_probe_options(Isa::automatic, microbench_rule());
    auto among = [](const auto& values, const auto& value) {
        return std::find(values.begin(), values.end(), value) != values.end();
    };
    double cycles = 0.0;
    for (const MicrobenchSample& s : samples)
        if (among(probe.kinds, s.kind) && among(probe.buffer_slots, s.slots) &&
            among(probe.lengths, s.lanes))
            cycles += s.cycles;
    return cycles;
}

double speed_probe_cycles(Isa isa, const ConvergenceRule& convergence, uint32_t probes) {
    const MicrobenchOptions options = speed_probe_options(isa, convergence);
    double fastest = std::numeric_limits<double>::infinity();
    for (uint32_t p = 0; p < std::max(1u, probes); ++p) {
        if (p) std::this_thread::sleep_for(std::chrono::seconds(1));
        double cycles = 0.0;
        for (const MicrobenchSample& s : run_stream_microbenchmarks(options)) cycles += s.cycles;
        fastest = std::min(fastest, cycles);
    }
    return fastest;
}

double speed_probe_drift(double cycles, double reference) {
    return reference > 0 ? cycles / reference - 1.0 : std::nan("");
}

double calibration_drift(const HostCalibration& c) {
    const double probe = speed_probe_drift(c.host.speed_probe_cycles, c.speed_probe_start_cycles);
    const double sweeps =
        c.sweep_probe_points_cycles > 0
            ? speed_probe_drift(c.sweep_probe_points_cycles, c.host.speed_probe_cycles)
            : std::nan("");
    if (std::isnan(probe)) return sweeps;
    if (std::isnan(sweeps)) return probe;
    return std::abs(sweeps) > std::abs(probe) ? sweeps : probe;
}

SeenLevel chase_last_level_now(double tsc_mhz) {
    HostDescription h;
    h.caches = read_host_caches();
    h.tsc_mhz = tsc_mhz;
    chase_last_level(h);
    if (h.last_level_chases.empty()) return {};
    return last_level_seen(h);
}

SeenLevel median_level(const std::vector<SeenLevel>& levels) {
    std::vector<double> kib, fills;
    for (const SeenLevel& seen : levels)
        if (seen.kib > 0) {
            kib.push_back(seen.kib);
            fills.push_back(seen.foreign_fill_per_us);
        }
    SeenLevel run;
    if (kib.empty()) return run;
    run.kib = uint32_t(std::llround(median(kib)));
    run.foreign_fill_per_us = median(fills);
    return run;
}

HwConfig with_last_level(const HwConfig& host, const SeenLevel& seen) {
    HwConfig c = host;
    if (seen.kib == 0 || c.scene_memory.caches.empty() || !c.scene_memory.caches.back().shared)
        return c;
    CacheLevelConfig& last = c.scene_memory.caches.back();
    // The run's median of two chases' sizes need not be whole sets.
    last.kib = whole_sets_kib(seen.kib, last.ways, last.line_bytes);
    last.foreign_fill_per_us = seen.foreign_fill_per_us;
    return c;
}

SiliconOrder silicon_order(const std::vector<SiliconVariant>& variants) {
    const size_t n = variants.size();
    SiliconOrder order;
    order.frames.resize(n);
    std::vector<uint32_t> place(n);           // among the workloads of its frames
    std::vector<uint32_t> per_frames, first;  // per frame group: workloads, first variant
    for (size_t v = 0; v < n; ++v) {
        const RenderSettings& a = variants[v].settings;
        uint32_t g = 0;
        for (; g < first.size(); ++g) {
            const SiliconVariant& f = variants[first[g]];
            if (f.scene == variants[v].scene && f.settings.width == a.width &&
                f.settings.height == a.height && f.settings.spp == a.spp &&
                f.settings.max_depth == a.max_depth && f.settings.seed == a.seed)
                break;
        }
        if (g == first.size()) {
            first.push_back(uint32_t(v));
            per_frames.push_back(0);
        }
        order.frames[v] = g;
        place[v] = per_frames[g]++;
    }
    order.rounds.resize(n);
    std::iota(order.rounds.begin(), order.rounds.end(), size_t(0));
    std::stable_sort(order.rounds.begin(), order.rounds.end(),
                     [&](size_t a, size_t b) { return place[a] < place[b]; });
    return order;
}

void keep_freed_memory_in_heap() {
    mallopt(M_MMAP_THRESHOLD, 32 << 20);  // glibc's largest (HEAP_MAX_SIZE / 2 on 64 bits)
    mallopt(M_TRIM_THRESHOLD, 1 << 30);
}

std::vector<SiliconMeasurement> predict_and_measure(
    const std::vector<SiliconVariant>& variants, const ConvergenceRule& convergence, uint64_t seed,
    const std::function<void(const std::string&, size_t, size_t)>& progress, bool memory_now) {
    keep_freed_memory_in_heap();
    const size_t n = variants.size();
    std::vector<SiliconMeasurement> out(n);
    std::vector<RenderSettings> settings(n);
    const double tsc_mhz = measure_tsc_mhz();
    if (progress) progress("chasing the L3", 0, n);
    const SeenLevel l3_before = chase_last_level_now(tsc_mhz);
    const SiliconOrder order = silicon_order(variants);
    for (size_t v = 0; v < n; ++v) {
        settings[v] = variants[v].settings;
        settings[v].threads = 1;
        settings[v].seed += k_frames_per_workload * order.frames[v];
        out[v].seed = settings[v].seed;
        out[v].l3_before = l3_before;
    }
    // The predictions, with the host file's L3 before the renders; with memory_now, after
    // them, with the run's L3 (SiliconMeasurement::l3_run), and for comparison the file's and
    // the one chased in the round of each workload's fastest render.
    auto frame_with = [&](size_t v, const HwConfig& host) {
        SiliconMeasurement other;
        predict(*variants[v].scene, *variants[v].bvh, settings[v], host, false, other);
        return other.predicted_frame;
    };
    auto predict_all = [&](const std::function<HwConfig(size_t)>& host_of) {
        for (size_t v = 0; v < n; ++v) {
            if (progress) progress("predicting", v, n);
            predict(*variants[v].scene, *variants[v].bvh, settings[v], host_of(v), variants[v].cold,
                    out[v]);
            out[v].predicted_frame_described = out[v].predicted_frame;
            if (memory_now) {
                out[v].predicted_frame_described = frame_with(v, *variants[v].host);
                out[v].predicted_frame_round =
                    frame_with(v, with_last_level(*variants[v].host, out[v].l3_render));
            }
        }
    };
    if (!memory_now) predict_all([&](size_t v) { return *variants[v].host; });
    // One cycle source per back end: its clock is measured under that back end's instructions.
    std::map<uint32_t, std::unique_ptr<CycleSource>> sources;
    for (size_t v = 0; v < n; ++v) {
        const uint32_t lanes = isa_width(resolve_isa(settings[v].isa));
        if (!sources.count(lanes)) sources[lanes] = std::make_unique<CycleSource>(lanes, tsc_mhz);
        out[v].cycle_source = sources[lanes]->description();
        out[v].cycles_counted = sources[lanes]->counted();
    }
    auto source_of = [&](size_t v) -> CycleSource& {
        return *sources[isa_width(resolve_isa(settings[v].isa))];
    };
    // The measurement: rounds in which every variant still short of convergence renders once
    // unclocked and once with the stage clock, in turn, so the machine's drift touches every
    // variant and both kinds alike. Stages: each stage's fewest TSC ticks over the
    // stage-clocked renders (a neighbour's time lands in whichever stage it interrupts, and
    // only ever adds), as fractions of their sum, times the frame's cycles. (The split of the
    // least interrupted render, as before, gave stage MAE 17.5/14.7/23.9 % on atrium and
    // conference against 15.0/14.5/22.2 % from the same renders.)
    std::vector<std::array<double, 3>> stage_min(n, {1e300, 1e300, 1e300});
    std::vector<std::array<double, 2>> short_loop_min(n, {1e300, 1e300});
    std::vector<std::array<double, 2>> short_loop_leaf_min(n, {1e300, 1e300});
    std::vector<std::array<double, k_op_kind_count>> shading_op_min(n);
    for (auto& kinds : shading_op_min) kinds.fill(1e300);
    std::vector<double> ray_setup_min(n, 1e300);
    std::vector<std::vector<double>> clocked_totals(n), tsc_samples(n);
    // Each part's ticks in the unclocked renders whose clock held, where the monitor's probes
    // around it found the core alone (clean_spans), the rest of each such render (its ticks
    // outside the parts), and the renders' cycles a tick (SiliconMeasurement::
    // measured_frame_parts).
    std::vector<std::vector<std::vector<double>>> part_clean(n);
    std::vector<std::vector<double>> part_rest(n);
    std::vector<std::vector<double>> cycles_per_tick(n);
    std::vector<std::vector<CycleReading>> readings(n);
    // With memory_now, the L3 chased at the start of each round, and each render's round.
    std::vector<SeenLevel> round_l3;
    std::vector<std::vector<uint32_t>> sample_round(n);
    RenderResult r;
    // Warm: the caches with the workload's own frame (what predict() starts from), page
    // faults, the tracer's buffers. A workload of the same scene before it leaves other lines:
    // a 128 x 128 frame after a 64 x 64 one finds a quarter of its own.
    size_t warm_variant = n;
    auto warm = [&](size_t v) {
        uint32_t ignored = 0;
        timed_render(*variants[v].scene, *variants[v].bvh, other_frame(settings[v], k_warm_frame),
                     false, source_of(v), tsc_mhz, r, ignored);
        warm_variant = v;
    };
    for (size_t v = 0; v < n; ++v) warm(v);
    // The machine's speed against calibration, per back end, before the renders and after.
    std::map<uint32_t, double> probe_before, probe_after;
    auto probe_all = [&](std::map<uint32_t, double>& probes) {
        for (size_t v = 0; v < n; ++v) {
            const uint32_t lanes = isa_width(resolve_isa(settings[v].isa));
            const double at_calibration = variants[v].host->speed_probe_cycles;
            if (!probes.count(lanes))
                probes[lanes] =
                    at_calibration > 0
                        ? speed_probe_drift(speed_probe_cycles(settings[v].isa, microbench_rule()),
                                            at_calibration)
                        : std::nan("");
        }
    };
    probe_all(probe_before);
    // Placement varies from render to render (Stabilizer's idea, for the heap alone): a block
    // of 0-64 KiB in 64-byte steps, held over the render, moves where the tracer's buffers land
    // relative to pages, cache sets and each other. The buffers renders keep are released after
    // it where a warming render comes next: it allocates them (and pays for their zeroing), the
    // stage-clocked and the measured render after it find them made, as the model's warm frame
    // does.
    std::mt19937_64 rng(seed);
    std::vector<uint64_t> others_busy(n, 0), others_total(n, 0);
    const int own_cpu = sched_getcpu();
    // A render whose estimated cycles rest on a clock that moved by more than the tolerance
    // (clock_moved) is set aside: it could pass for the fastest (or not) by the clock alone.
    // It spends the budget as a render does.
    auto frame_rule = [&](size_t v) { return after_discarded(convergence, out[v].clock_moved); };
    // A render the core was found shared over (below) is set aside and taken again, at most the
    // budget's number of times; then the workload stops, judged on the renders it kept (its
    // cold renders too, which follow kept ones only: without the stop a workload whose every
    // render was shared would render for ever to complete them).
    auto needs_more = [&](size_t v) {
        if (out[v].contended >= convergence.budget || out[v].clock_moved >= convergence.budget)
            return false;
        return needs_more_samples(out[v].frame_samples, frame_rule(v)) ||
               (variants[v].cold && needs_more_samples(out[v].cold_samples, convergence));
    };
    for (uint32_t round = 1;; ++round) {
        size_t open = 0;
        for (size_t v = 0; v < n; ++v) open += needs_more(v);
        if (open == 0) break;
        if (progress)
            progress("round " + std::to_string(round) + ": " + std::to_string(open) + " open",
                     n - open, n);
        if (memory_now) {
            round_l3.push_back(chase_last_level_now(tsc_mhz));
            warm_variant = n;  // the chases evicted the caches a render warmed
        }
        for (const size_t v : order.rounds) {
            SiliconMeasurement& m = out[v];
            if (!needs_more(v)) continue;
            const Scene& scene = *variants[v].scene;
            const Bvh& bvh = *variants[v].bvh;
            std::vector<char> shift(64 * size_t(rng() % 1024));
            if (warm_variant != v) {
                release_kept_ray_buffers();  // the warming render's are allocated after the block
                warm(v);
            }
            // The stage-clocked render comes before the measured one, so that two renders of
            // the workload (other frames of it) precede it: one left temple's 64 x 64 frame in
            // 16-pixel tiles 11-13 % slower (45.2 against 39.5-39.9 Mcycles, scalar) whenever
            // another scene's workloads ran before it, a state the caches' replacement had not left
            // yet (the model's warm frames: predict()).
            const CycleReading clocked =
                timed_render(scene, bvh, other_frame(settings[v], k_clocked_frame), true,
                             source_of(v), tsc_mhz, r, m.interrupted)
                    .first;
            for (int s = 0; s < 3; ++s)
                stage_min[v][size_t(s)] =
                    std::min(stage_min[v][size_t(s)], double(r.stats.stage_tsc[s]));
            for (int l = 0; l < 2; ++l) {
                short_loop_min[v][size_t(l)] =
                    std::min(short_loop_min[v][size_t(l)], double(r.stats.short_loop_tsc[l]));
                short_loop_leaf_min[v][size_t(l)] = std::min(
                    short_loop_leaf_min[v][size_t(l)], double(r.stats.short_loop_leaf_tsc[l]));
            }
            for (uint32_t k = 0; k < k_op_kind_count; ++k)
                shading_op_min[v][k] =
                    std::min(shading_op_min[v][k], double(r.stats.shading_op_tsc[k]));
            ray_setup_min[v] = std::min(ray_setup_min[v], double(r.stats.ray_setup_tsc));
            clocked_totals[v].push_back(clocked.cycles);
            // Where the gate slept, the render before no longer warms this one: others' fills
            // over 10-30 ms asleep took what it left in a shared L3 (base/core_contention.h).
            const bool alone_before = core_contention().wait_warm([&] {
                warm(v);
                ++m.rewarmed;
            });
            const uint64_t waited_at = read_tsc();
            const std::vector<CpuTimes> load_before = read_cpu_times();
            ContentionMonitor monitor(core_contention().shared_below(), k_monitor_period_us);
            auto [reading, ticks] = timed_render(scene, bvh, settings[v], false, source_of(v),
                                                 tsc_mhz, r, m.interrupted);
            ContentionMonitor::Tally probed = monitor.stop();
            const std::vector<CpuTimes> load_after = read_cpu_times();
            // The monitor's probes ran in the render's thread: their ticks at the render's clock
            // come off its cycles (the signals' delivery, a few hundred cycles each, stays in).
            const double monitor_cycles = probed.probe_ticks *
                                          (reading.clock_mhz_before + reading.clock_mhz_after) /
                                          (2.0 * tsc_mhz);
            reading.cycles = std::max(0.0, reading.cycles - monitor_cycles);
            m.render_cycles.push_back(reading.cycles);
            m.render_shared_share.push_back(probed.probes ? double(probed.shared) / probed.probes
                                                          : 0.0);
            // Shared: over more than a tenth of the monitor's probes (a burst of a millisecond
            // or two in a render of 50 ms is within what the fastest renders' agreement
            // tolerates), or just after it, as the gate finds it (a render of a millisecond or
            // two may see no probe).
            const uint64_t checked_at = read_tsc();
            const bool shared_after = core_contention().contended();
            const bool shared = probed.shared > 0.1 * probed.probes || shared_after;
            // The gate's checks just before and after the render are probes too: the first
            // and last parts have one on their far side.
            probed.marks.insert(probed.marks.begin(), {waited_at, !alone_before});
            probed.marks.push_back({checked_at, shared_after});
            const std::vector<uint64_t>& parts = r.stats.part_tsc;
            if (part_clean[v].empty()) part_clean[v].resize(parts.size());
            if (parts.size() == part_clean[v].size() &&
                clock_moved(reading) <= convergence.tolerance && ticks > 0) {
                std::vector<std::pair<uint64_t, uint64_t>> spans;
                double sum = 0.0;
                for (size_t p = 0; p < parts.size(); ++p) {
                    spans.push_back(
                        {r.stats.part_start_tsc[p], r.stats.part_start_tsc[p] + parts[p]});
                    sum += double(parts[p]);
                }
                // A probe within one and a half periods of a part: the next one after it or
                // the one before (a signal can come late by a little).
                const std::vector<bool> clean =
                    clean_spans(probed.marks, spans, uint64_t(1.5 * k_monitor_period_us * tsc_mhz));
                for (size_t p = 0; p < parts.size(); ++p)
                    if (clean[p]) part_clean[v][p].push_back(double(parts[p]));
                part_rest[v].push_back(std::max(0.0, ticks - sum));
                cycles_per_tick[v].push_back(reading.cycles / ticks);
            }
            for (size_t c = 0; c < load_before.size() && c < load_after.size(); ++c)
                if (int(c) != own_cpu) {
                    others_busy[v] += load_after[c].busy - load_before[c].busy;
                    others_total[v] += load_after[c].total - load_before[c].total;
                }
            if (clock_moved(reading) > convergence.tolerance) {
                ++m.clock_moved;
                continue;
            }
            // One over which another hardware thread shared the core (base/core_contention.h:
            // the core is waited for before each render, probed during it and after it) is set
            // aside too; until 2026-12-03 only the probe after it counted, and once the budget's
            // number were set aside, shared renders were kept (a workload of temple converged
            // on renders 80-90 % of whose probes found the core shared).
            if (shared) {
                ++m.contended;
                continue;
            }
            m.frame_samples.push_back(reading.cycles);
            m.monitor_share += monitor_cycles / std::max(1.0, reading.cycles + monitor_cycles);
            sample_round[v].push_back(round - 1);
            readings[v].push_back(reading);
            tsc_samples[v].push_back(ticks);
            const int64_t huge = anon_huge_page_kib();
            m.huge_page_kib_min =
                m.huge_page_kib_min < 0 ? huge : std::min(m.huge_page_kib_min, huge);
            m.huge_page_kib_max = std::max(m.huge_page_kib_max, huge);
            if (variants[v].cold) {
                evict_caches();
                m.cold_samples.push_back(timed_render(scene, bvh,
                                                      other_frame(settings[v], k_cold_frame), false,
                                                      source_of(v), tsc_mhz, r, m.interrupted)
                                             .first.cycles);
                warm_variant = n;  // one render since the eviction: not yet the warm state
            }
        }
    }
    probe_all(probe_after);
    if (progress) progress("chasing the L3", n, n);
    const SeenLevel l3_after = chase_last_level_now(tsc_mhz);
    for (size_t v = 0; v < n; ++v) {
        SiliconMeasurement& m = out[v];
        m.l3_after = l3_after;
        const uint32_t lanes = isa_width(resolve_isa(settings[v].isa));
        m.probe_before = probe_before[lanes];
        m.probe_after = probe_after[lanes];
        m.convergence = judge_convergence(m.frame_samples, frame_rule(v));
        m.measured_frame = m.convergence.fastest;
        if (!part_clean[v].empty() && !cycles_per_tick[v].empty()) {
            std::vector<std::vector<double>> parts = part_clean[v];
            parts.push_back(part_rest[v]);
            m.parts_convergence = judge_parts_convergence(parts, convergence);
            m.measured_frame_parts = m.parts_convergence.fastest * median(cycles_per_tick[v]);
            m.frame_parts = uint32_t(part_clean[v].size());
        }
        if (m.frame_samples.empty()) continue;  // every render set aside: nothing measured
        m.monitor_share /= double(m.frame_samples.size());
        if (variants[v].cold) {
            m.cold_convergence = judge_convergence(m.cold_samples, convergence);
            m.measured_cold_frame = m.cold_convergence.fastest;
        }
        const size_t fastest = size_t(
            std::min_element(m.frame_samples.begin(), m.frame_samples.end()) -
            m.frame_samples.begin());
        if (memory_now) {
            m.l3_render = round_l3[sample_round[v][fastest]];
            for (uint32_t round_index : sample_round[v]) {
                m.frame_sample_l3_kib.push_back(round_l3[round_index].kib);
                m.frame_sample_l3_fill_per_us.push_back(round_l3[round_index].foreign_fill_per_us);
            }
            for (const SeenLevel& seen : round_l3) {
                m.l3_rounds_kib_min = std::min(m.l3_rounds_kib_min, seen.kib);
                m.l3_rounds_kib_max = std::max(m.l3_rounds_kib_max, seen.kib);
            }
        }
        m.clock_mhz_before = readings[v][fastest].clock_mhz_before;
        m.clock_mhz_after = readings[v][fastest].clock_mhz_after;
        m.measured_frame_tsc = median(tsc_samples[v]);
        if (others_total[v] > 0)
            m.neighbours_busy = double(others_busy[v]) / double(others_total[v]);
        const double stages = stage_min[v][0] + stage_min[v][1] + stage_min[v][2];
        for (int s = 0; s < 3; ++s)
            m.measured_stage[size_t(s)] =
                stages > 0 ? stage_min[v][size_t(s)] / stages * m.measured_frame : 0.0;
        // A stage by loop: the short loops' fewest ticks split as the stages are, the stream
        // loop the rest of the stage.
        const auto by_loop = [&](double stage, const std::array<double, 2>& short_loops) {
            std::array<double, 3> loops{0.0, 0.0, stage};
            for (size_t l = 0; l < 2; ++l) {
                loops[l] = stages > 0 ? short_loops[l] / stages * m.measured_frame : 0.0;
                loops[2] = std::max(0.0, loops[2] - loops[l]);
            }
            return loops;
        };
        m.measured_loop = by_loop(m.measured_stage[0], short_loop_min[v]);
        m.measured_leaf_loop = by_loop(m.measured_stage[1], short_loop_leaf_min[v]);
        const double tick_cycles = stages > 0 ? m.measured_frame / stages : 0.0;
        // The stage clock times shading kinds only: the others stay 0.
        for (uint32_t k = 0; k < k_op_kind_count; ++k)
            m.measured_shading_op[k] = shading_op_min[v][k] * tick_cycles;
        m.measured_ray_setup = ray_setup_min[v] * tick_cycles;
        m.stage_clock_overhead =
            *std::min_element(clocked_totals[v].begin(), clocked_totals[v].end()) /
                m.measured_frame -
            1.0;
    }
    if (memory_now) {
        std::vector<SeenLevel> met;  // each kept render's round's
        for (size_t v = 0; v < n; ++v)
            for (uint32_t round_index : sample_round[v]) met.push_back(round_l3[round_index]);
        const SeenLevel run = median_level(met);
        for (SiliconMeasurement& m : out) m.l3_run = run;
        predict_all([&](size_t v) { return with_last_level(*variants[v].host, run); });
    }
    return out;
}

}  // namespace sfx
