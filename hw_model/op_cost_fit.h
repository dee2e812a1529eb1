#pragma once
// A CPU core's per-op costs (HwConfig::op_costs) fitted on microbenchmarks of the native filters
// (kernels/stream/stream_microbench.h), never on frames. The costs are priced where every op is
// priced, OpProfile::issue_cycles (hw_model/op_costs.h); the fit's error is measured through it.

#include <algorithm>
#include <array>
#include <cstdint>
#include <string>
#include <utility>
#include <vector>

#include "hw_model/hw_config.h"
#include "kernels/trace.h"

namespace sfx {

// Cycles under which a microbenchmark sample is mostly the time-stamp counter's granularity
// (it steps by tens of ticks on some machines) and counts as this many in relative errors.
constexpr double k_fit_resolution_cycles = 100.0;

// An op's measured cost: OpProfile::issue_cycles over its groups (n lanes, p passing, a share
// `beyond_l1` of the lanes paying for ray slots outside the L1D, beyond_cache_share, and
// `beyond_l2` for slots outside the L2 as well, `beyond_l1_skipping` outside the L1D skipping lines
// in a page the lane before opened, beyond_cache_skipping_share, `beyond_tlb` opening a page
// beyond the first-level DTLB's reach, beyond_tlb_share; `failed_candidates` of the failing
// lanes candidates that ran the full test (0: none; a mean where the ops of a traversal sample are
// priced by their kind and length); one lane: one_lane_cycles when measured).
double measured_op_cycles(const OpCostConfig& cost, uint32_t width, uint32_t lanes, uint32_t passed,
                          double beyond_l1, double beyond_l2 = 0.0, double failed_candidates = 0.0,
                          double beyond_l1_skipping = 0.0, double beyond_tlb = 0.0);

// One microbenchmark run of an op kind: what the cost formula sees, and the cycles measured.
struct OpCostSample {
    uint32_t lanes = 0, passed = 0;
    double beyond_l1 = 0.0;
    double cycles = 0.0;  // per op
    uint32_t failed_candidates = 0;  // StreamOp::failed_candidates
    double beyond_l2 = 0.0;          // of the lanes, those beyond the L2 as well
    double beyond_l1_skipping = 0.0;  // beyond the L1D, skipping lines in an opened page
    double beyond_tlb = 0.0;          // opening a page beyond the first-level DTLB's reach
};

// Fits an op kind's cost profile to its samples: least squares on relative error, every
// coefficient non-negative (a negative one is dropped and the rest refitted). Throws
// std::invalid_argument on no samples.
OpCostConfig fit_op_cost(const std::string& op, uint32_t width,
                         const std::vector<OpCostSample>& samples);

// What a variant of an op adds per passing lane over the op's fitted cost (`base`): the median
// over the variant's samples with passing lanes of their cycles beyond `base`'s, per passing
// lane; 0 when there are none, never negative. A thin-lens camera over a pinhole (every lane
// passes: OpCostConfig::thin_lens_per_lane_cycles), a sphere light's direct-light samples over a
// quad's (sphere_light_per_pass_cycles: a failing lane costs the same on either).
double fit_extra_per_passing_lane(const OpCostConfig& base, uint32_t width,
                                  const std::vector<OpCostSample>& variant_samples);
// Likewise per lane, and signed (negative where the variant's lanes cost less): the emission
// filter's microbenchmarks on sphere hits over its fitted cost on triangle hits
// (OpCostConfig::sphere_hit_per_lane_cycles).
double fit_extra_per_lane(const OpCostConfig& base, uint32_t width,
                          const std::vector<OpCostSample>& variant_samples);
// A shading op's cold call over a warm one (OpCostConfig::cold_call_cycles) from its points'
// differences, one a stream length: their median (a long call's difference is the noisiest),
// 0 where that is negative or there are none.
double fit_cold_call_cycles(std::vector<double> differences);
// Likewise per failed candidate: the triangle test's microbenchmark of failing candidates over
// the op's fitted cost, whose failing lanes are lanes the float stage rejects
// (OpCostConfig::per_failed_candidate_cycles).
double fit_extra_per_failed_candidate(const OpCostConfig& base, uint32_t width,
                                      const std::vector<OpCostSample>& variant_samples);

// A leaf test's one-lane costs from its one-lane samples, by the lane's outcome: one_lane_cycles
// is the median of those whose lane fails (of every sample where none fails),
// one_lane_pass_cycles and one_lane_failed_candidate_cycles the medians of those whose lane
// passes and of those whose lane is a failed candidate beyond it (0 where either side has no
// sample; never negative). The rest of `cost` is kept, and all of it without samples: an op
// with no one-lane samples (every op but the triangle and sphere tests) is priced on one lane by
// the formula. Until 2026-12-07 it was priced at the median of none, 0, between its fit and the
// short-stream costs that set it unmeasured again: its one-lane points' fit error read 100 %
// and the extras fitted in between (thin lens, sphere light, sphere hits) took those points'
// whole cost for their own.
void fit_one_lane_by_outcome(OpCostConfig& cost, const std::vector<OpCostSample>& one_lane);

// The fit's relative error on its own samples: (median, worst) of |predicted - measured| /
// measured, a measurement under 100 cycles counting as 100 (the clock's steps).
std::pair<double, double> fit_error(const OpCostConfig& cost, uint32_t width,
                                    const std::vector<OpCostSample>& samples);

// Traversals timed together (kernels/stream/stream_microbench.h): how many ops each kind made
// in the one-ray loop (one lane), in the few-ray loop (a wide back end's box tests of 2 to
// k_few_ray_lanes lanes) and in the stream loop (the rest); the cycles priced before the fit
// (stream_op_cycles: the stream loop's ops beyond their per-op costs, their groups and lanes, as
// the stream formula prices them (OpProfile::issue_cycles with the fitted per-op costs), and
// one-lane ops whose cost was timed directly, which `ops` then leaves out); and the cycles they
// took.
struct OneLaneSample {
    std::array<uint64_t, k_op_kind_count> ops{};
    double cycles = 0.0;
    std::array<uint64_t, k_op_kind_count> few_ops{};
    double stream_op_cycles = 0.0;
    std::array<uint64_t, k_op_kind_count> stream_ops{};
    std::array<uint64_t, 2> entries{};  // the one-ray and few-ray loops entered (TraversalLoop)
    uint64_t traversals = 0;            // traversals started (StreamOp::starts_traversal)
    double leaf_op_cycles = 0.0;  // the leaf tests' part of stream_op_cycles (reported)
    // The leaf tests' part of `cycles` by the stage clock (OneRaySample::leaf_share), which the
    // fit takes instead of leaf_op_cycles; negative where none was clocked.
    double leaf_cycles_clocked = -1.0;
    // The one-ray and few-ray loops' part of `cycles` less their leaves by the same clock
    // (OneRaySample::short_loop_share), negative where not clocked; of `ops`' one-lane box
    // tests, those the few-ray loop runs (OneRaySample::few_ray_one_lane_box_ops); and of
    // stream_op_cycles, the box tests' mispredictions priced in the one-ray and few-ray loops.
    std::array<double, 2> loop_cycles_clocked{-1.0, -1.0};
    uint64_t few_ray_one_lane_box_ops = 0;
    std::array<double, 2> loop_mispredicted_cycles{};
};
// Of a sample's one-lane box tests, those the few-ray loop runs (below a stream of 2 to
// k_few_ray_lanes rays: the stage clock counts them there), priced at the one-lane cost.
inline double few_ray_one_lane_box_tests(const OneLaneSample& s) {
    return double(std::min<uint64_t>(s.few_ray_one_lane_box_ops, s.ops[size_t(OpKind::box_test)]));
}

// The one-lane and few-lane costs of every kind the samples make (OpCostConfig::
// one_lane_cycles, few_lane_cycles; not measured, negative, for the rest) and the per-op cost in a
// traversal of every kind the samples' stream loops make (OpCostConfig::per_op_cycles): there each
// op waits for the one before's output, where the filter microbenchmarks time independent calls,
// which a core overlaps (an op's groups are independent in both, so their cost stays the filters').
// Least squares on relative error of the cycles beyond the stream-priced groups and lanes and
// beyond the leaf tests as the stage clock splits them off (leaf_cycles_clocked, where clocked:
// the leaf tests' costs are the filter microbenchmarks', and what those miss in a traversal is
// not the traversal's to absorb), non-negative as in fit_op_cost. Where the clock split the
// loops too (loop_cycles_clocked), each loop is a row of its own: the one-ray loop's ops and
// entries against its clocked cycles, the few-ray loop's likewise, the stream loop's per-op
// costs and traversal starts against the rest; the rows sum to the whole sample's, and each
// loop's cost is told from the others' by where the time went, not only by how the batches
// mix them (fitted on the whole, the few-ray loop's box cost and the stream loop's traded: an
// AMD Zen 5 VM's AVX2 batches' few-ray loop and rest priced 4.6 % over and 10.5 % under their
// clocked parts on 2026-12-06, -1.3 % and +0.2 % by loop on 2026-12-07).
// Errors stay relative to the whole sample's cycles. Throws std::invalid_argument on no samples.
struct ShortStreamCosts {
    std::array<double, k_op_kind_count> one_lane{}, few_lane{}, stream_per_op{};
    std::array<bool, k_op_kind_count> stream_measured{};  // the samples' stream loops made it
    // The samples had such ops (a term at 0 is then a fitted 0, not a missing one).
    std::array<bool, k_op_kind_count> one_lane_measured{}, few_lane_measured{};
    // What entering the one-ray and the few-ray loop costs besides their ops (OpCostConfig::
    // one_ray_entry_cycles, few_ray_entry_cycles).
    std::array<double, 2> entry{};
    // What starting a traversal costs besides its ops (OpCostConfig::traversal_start_cycles).
    double traversal_start = 0.0;
};
// The few-ray loop's box cost and entry cost given, not fitted (GivenFewRayCosts): they are
// priced out of the samples and returned as given.
struct GivenFewRayCosts {
    double few_lane_cycles = 0.0, entry_cycles = 0.0;
};
ShortStreamCosts fit_short_stream_cycles(const std::vector<OneLaneSample>& samples,
                                         const GivenFewRayCosts* given = nullptr);
// A sample's cycles as the fitted costs price it.
double short_stream_cycles(const ShortStreamCosts& costs, const OneLaneSample& sample);

// That fit's (median, worst) relative error on its own samples (of their whole cycles).
std::pair<double, double> short_stream_fit_error(const ShortStreamCosts& costs,
                                                 const std::vector<OneLaneSample>& samples);

// The surface-read microbenchmark (kernels/stream/stream_microbench.h) as the fit sees it: a
// stream of hits on a mesh of `triangles` (the hit primitives of the repetitions before, then of
// the timed one), and the cycles it took beyond the same stream on a cache-resident mesh.
struct HitReadSample {
    uint32_t triangles = 0;
    std::vector<uint32_t> warm_prims, timed_prims;
    double extra_cycles = 0.0;
};

// The cache model's latency beyond an L2 hit (hit_read_latency_hidden) of a sample's timed reads
// from the mesh's arrays, summed, on `host`'s scene memory: hit_latency_beyond
// (hw_model/op_costs.h), as CoreModel::request_scene prices a CPU core's lanes, one op's lanes
// requested together, after the mesh (written in order when it was built) and the earlier
// repetitions' reads warmed the caches.
double modeled_hit_read_cycles(const HwConfig& host, const HitReadSample& sample);

// OpCostConfig::hit_read_exposed_share: the share s with s x modeled = extra, least squares on
// relative error over the samples (a sample's extra floored at one cycle a lane), not below 0;
// with its (median, worst) relative error. Throws std::invalid_argument on no samples.
struct HitReadFit {
    double share = 0.0;
    std::pair<double, double> error{};
    std::vector<double> modeled;  // per sample
};
HitReadFit fit_hit_read_exposed_share(const HwConfig& host,
                                      const std::vector<HitReadSample>& samples);

}  // namespace sfx
