#pragma once
// The host CPU as a hardware configuration, validated on silicon: describe the host and fit its
// per-op costs on microbenchmarks of the native filters (never on frames), then, for a held-out
// workload, predict the native stream tracer's single-thread cycles with the machine model on
// the trace of the same render (run_point_group at full fidelity, as sfx simulate) and measure
// them (trace off, one pinned thread): core cycles from base/cycle_source.h (counted, or
// estimated with the back end's own clock), each workload rendered until its fastest renders
// agree (base/convergence.h) or its budget runs out.

#include <array>
#include <cstdint>
#include <functional>
#include <memory>
#include <string>
#include <vector>

#include "base/convergence.h"
#include "hw_model/branch_predictor.h"
#include "hw_model/host_description.h"
#include "hw_model/op_cost_fit.h"
#include "hw_model/prediction.h"
#include "hw_model/workload_shape.h"
#include "kernels/bvh.h"
#include "kernels/render.h"
#include "kernels/stream/stream_microbench.h"
#include "workloads/scene.h"

namespace sfx {

// A predictor microbenchmark's batches of one kind (kernels/stream/stream_microbench.h) as
// measured, and the model's predictor on the same batches (hw_model/branch_predictor.h).
struct PredictorCheck {
    PredictorSample measured;
    PredictorStates modelled;  // the TAGE's (simulate_predictor_states)
    PredictorStates unseen;    // the unseen-ops predictor's (unseen_ops_states)
    // The batches' traces and their scene's shape, for the model to time (model_batch_memory).
    std::vector<std::shared_ptr<const PassBuffer>> batches;
    WorkloadShape shape;
};
// run_predictor_microbenchmarks on `scene` (its BVH `bvh`) with `isa` (`time_evicted` as
// there), and the model's predictors on each batch's trace at that back end's width.
std::vector<PredictorCheck> check_predictor(const Scene& scene, const Bvh& bvh, Isa isa,
                                            const ConvergenceRule& convergence,
                                            bool time_evicted = true);

// BranchPredictorConfig's costs by loop (one-ray, few-ray, stream) from the branch
// microbenchmark's samples: per loop, what the displaced batches took beyond the cached ones in
// that loop (the stage clock's split) over the box tests' mispredictions the model adds there
// from primed to displaced, pooled over the samples; -1 (the pooled cost) for a loop holding
// under k_loop_mispredict_min_share of the box tests' added mispredictions.
std::array<double, 3> fit_loop_mispredict_cycles(const std::vector<PredictorCheck>& samples);
// The states of `check` the predictor of kind `kind` (BranchPredictorConfig) models.
const PredictorStates& modelled_states(const PredictorCheck& check, const std::string& kind);
// BranchPredictorConfig's costs for kind "unseen_ops" from the branch microbenchmark's samples:
// by loop, what the displaced batches took beyond the cached ones in that loop (the stage
// clock's split) over the box tests the loop ran, pooled over the samples (-1 where a loop ran
// none); and `leaf` (mispredict_cycles, which prices the leaf tests): what they took beyond the
// cached ones outside the loops over the leaf tests.
struct UnseenOpCosts {
    std::array<double, 3> box_by_loop{-1.0, -1.0, -1.0};
    double leaf = 0.0;
};
UnseenOpCosts fit_unseen_op_cycles(const std::vector<PredictorCheck>& samples);
constexpr double k_loop_mispredict_min_share = 0.1;

// The model's cycles for a predictor microbenchmark's batches on `host` (its branches not
// priced: the states compared share the predictor's), each batch from empty caches (cold: the
// microbenchmark's evicted state) and right after itself (warm: primed), summed: how the model
// prices scene data from DRAM, held out against the evicted batches. With `after_others`, each
// batch also right after itself and then the other batches of its kind (displaced: its own
// lines aged by the others', the microbenchmark's displaced state as far as the caches go and
// its cached state as far as the scene's lines go).
// Each state split as the microbenchmark's are (BatchStateCycles): the box tests by the loop
// that runs them (FrameTiming::traversal_loop_cycles), the leaves' tests by the loop whose leaf
// code runs them (FrameTiming::intersection_loop_cycles).
struct BatchMemoryCycles {
    BatchStateCycles cold, warm, displaced;
};
BatchMemoryCycles model_batch_memory(const HwConfig& host, const PredictorCheck& sample,
                                     bool after_others = false);

// OpCostConfig::node_read_exposed_share, the box test's: per sample (a predictor check of the
// branch microbenchmark, its evicted state timed), what reading the scene from DRAM added to
// the short loops (one-ray and few-ray), measured (evicted - primed) less the same of the
// synthetic scene's batches of the same rays, whose scene is a few lines (`baseline`: the
// code, TLB and page tables the read evicts too), against the model's cold - warm in those
// loops (model_batch_memory); the share in [0, 1] whose cold - warm has the least squared
// error, with the model's extra at the whole latency and at that share, and its (median, worst)
// error relative to the measured extra. `given_share`, where given (another wide back end's
// file: FewRayFrom): that share is used, and judged, instead of the one found here, which is
// kept beside it (own_share). Throws std::invalid_argument on no samples.
struct NodeReadFit {
    double share = 1.0;
    double own_share = 1.0;  // the share these samples alone fit
    bool given = false;      // share came from another back end's file
    std::pair<double, double> error{};
    std::vector<double> measured, modeled_whole, modeled;  // per sample
};
NodeReadFit fit_node_read_exposed_share(const HwConfig& host,
                                        const std::vector<PredictorCheck>& samples,
                                        const std::vector<PredictorSample>& baseline,
                                        const double* given_share = nullptr);

struct HostCalibration {
    HostDescription host;
    std::vector<OpCostConfig> op_costs;
    std::vector<MicrobenchSample> samples;
    std::vector<KernelRate> rates;  // field read and compress by themselves (reported, not fitted)
    // Per fitted kind: the fit's (median, worst) relative error on its own samples, and its
    // costs as the filter microbenchmarks alone fitted them (op_costs then takes the
    // traversals' per-op box cost: set_short_stream_costs).
    std::vector<std::pair<double, double>> fit_errors;
    std::vector<OpCostConfig> filter_costs;
    // Per fitted kind, the fit's median signed error (priced over measured, less 1) on its
    // samples at each microbenchmark buffer (`residual_buffer_slots`, MicrobenchOptions::
    // buffer_slots; NaN where it has none): a trend along the buffers is a cost of the buffer's
    // size that the form (ray data beyond the L1D, beyond the L2) does not price.
    std::vector<uint32_t> residual_buffer_slots;
    std::vector<std::vector<double>> residuals_by_buffer;
    // The same on the largest buffer by stream length (`residual_lengths`, MicrobenchOptions::
    // lengths): a trend along them, at one buffer, is a cost of a stream's density (its lanes'
    // share of the buffer's pages) that the form does not price.
    std::vector<uint32_t> residual_lengths;
    std::vector<std::vector<double>> residuals_by_length;
    // Traversals, and the one- and few-lane costs' fit error on them (OpCostConfig::
    // one_lane_cycles of the box, triangle and sphere tests, few_lane_cycles of a wide back
    // end's box test, and the box test's per_op_cycles in the stream loop).
    std::vector<OneRaySample> one_ray_samples;
    SharedOriginSample shared_origin;  // OpCostConfig::shared_origin_per_lane_cycles
    // A traversal's start cold over warm, per length of cold_traversal_lengths (the box test's
    // OpCostConfig::cold_call_cycles: run_cold_traversal_microbenchmarks).
    std::vector<uint32_t> cold_traversal_lengths = {16, 32, 64};
    std::vector<double> cold_traversal_cycles;
    std::pair<double, double> short_stream_fit_errors{};
    // The same samples as that fit sees them, and what it fitted (for the report's residuals).
    std::vector<OneLaneSample> short_stream_samples;
    ShortStreamCosts short_stream_costs;
    // The hits' surfaces read beyond the caches, and the fitted share of their modelled latency
    // the core leaves exposed (OpCostConfig::hit_read_exposed_share).
    std::vector<SurfaceReadSample> surface_read_samples;
    HitReadFit hit_read_fit;
    // The branch microbenchmark (check_predictor on branch_microbench_scene) and the model's
    // mispredictions on its batches, on which HostDescription::branch_predictor's cost is fitted.
    std::vector<PredictorCheck> branch_samples;
    // The synthetic scene's predictor batches (run_predictor_microbenchmarks), what evicting
    // costs beyond the scene, and the short loops' exposed share of a node read's latency
    // fitted on the branch microbenchmark's evicted batches
    // (OpCostConfig::node_read_exposed_share).
    std::vector<PredictorSample> eviction_baseline;
    NodeReadFit node_read_fit;
    // The speed probe before the microbenchmarks (HostDescription::speed_probe_cycles is the
    // one after them): a calibration whose probe moved between the two measured a machine
    // that changed under it.
    double speed_probe_start_cycles = 0.0;
    // The probe's points as the microbenchmarks' sweeps timed them (speed_probe_points_cycles):
    // a slow spell over the sweeps, between the two probes, shows as their drift from the probe
    // after them (calibration_drift). On the Zen 4 VM (2026-12-04) one calibration's sweeps ran
    // 25-40 % slow (the triangle test 39.0 cycles a lane against 27.4-27.5 in the refits around
    // it) while its probes, before and after, read as the others'.
    double sweep_probe_points_cycles = 0.0;
    // Microbenchmark points (filters and one-ray batches) whose repetitions converged, of all.
    uint32_t converged_points = 0, points = 0;
    // Sweeps over the filter microbenchmarks' points (MicrobenchOptions::visits).
    uint32_t microbench_visits = 0;
    std::string yaml;  // host.hw.yaml
};

// The traversal samples as the one- and few-lane fit sees them (fit_short_stream_cycles): each
// sample's other ops (its leaves' tests, and its stream-loop box tests' lanes) priced by
// `costs`, the stream formula of a back end of `width` lanes, over the sample's buffer (its
// slots, the native slot size) beside the host's `caches` (its L1D and L2) and DTLB of
// `dtlb_pages` (lanes_beyond_caches);
// and the model's mispredictions on
// its batch (OneRaySample::modelled_mispredictions) as `predictor` prices them (a box test's
// by its loop), which the model adds to every traversal it times, so that the fitted costs do
// not hold them twice.
std::vector<OneLaneSample> short_stream_fit_samples(const std::vector<OneRaySample>& samples,
                                                    const std::vector<OpCostConfig>& costs,
                                                    uint32_t width,
                                                    const std::vector<HostCacheLevel>& caches,
                                                    const BranchPredictorConfig& predictor = {},
                                                    uint32_t dtlb_pages = 0);

// The shares of a microbenchmark stream's `lanes` lanes of `kind` over `slots` slots of the native
// tracer's buffers that pay for ray data beyond the L1D and beyond the L2 as well
// (beyond_cache_share with the first and the second of the host's `caches`; none beyond the
// L2 where it has one level), and that open a page beyond the reach of a first-level DTLB of
// `dtlb_pages` pages (beyond_tlb_share; 0: none).
struct LanesBeyondCaches {
    double l1 = 0.0, l2 = 0.0;
    double l1_skipping = 0.0;  // beyond the L1D, skipping lines in a page the lane before opened
    double tlb = 0.0;          // opening a page beyond the DTLB's reach
};
LanesBeyondCaches lanes_beyond_caches(OpKind kind, uint32_t lanes, uint32_t slots,
                                      const std::vector<HostCacheLevel>& caches,
                                      uint32_t dtlb_pages = 0);

// Whether any of the microbenchmarks' ray buffers of `buffer_slots` slots lies partly beyond
// the L2 of `caches` (beyond_cache_fraction, whose share lanes_beyond_caches prices; false
// without an L2). Where none does,
// beyond_l2_per_lane_cycles is left 0, not measured, and the host file says so: a 64 x 64
// tile's 1.3 MiB lies beyond a 1 MiB L2 but inside a 2 MiB one (an Intel Xeon VM, 2026-12-06:
// at 128x128 the model priced a 128-pixel tile's frame within 1 % of a 64-pixel one's, where
// the host ran it 11-15 % dearer, cornell and furnace on every back end).
bool microbenchmarks_reach_beyond_l2(const std::vector<uint32_t>& buffer_slots,
                                     const std::vector<HostCacheLevel>& caches);

// The traversal samples' cycles by part, as the stage clock splits them (OneRaySample::
// short_loop_share, leaf_share: the one-ray and few-ray loops less their leaves, the leaf tests,
// the rest) and as the fitted costs price them: `costs` on the fit's samples (`fitted`, from
// short_stream_fit_samples on the same `samples`), the box tests' mispredictions in each loop
// at `predictor`'s price there. Reported beside the fit, which takes the same split as its rows
// (fit_short_stream_cycles) and is judged on the batches' whole cycles: the clock's reads in a
// short loop's interval (rdtsc is not ordered with the work around it) blur the split as they
// blur a frame's, which the check splits with the same clock.
struct ShortStreamPart {
    double measured = 0.0, priced = 0.0;
};
struct ShortStreamSplit {
    ShortStreamPart one_ray, few_ray, leaves, rest;
};
ShortStreamSplit short_stream_split(const ShortStreamCosts& costs,
                                    const std::vector<OneLaneSample>& fitted,
                                    const std::vector<OneRaySample>& samples,
                                    const BranchPredictorConfig& predictor);

// run_one_ray_microbenchmarks' PredictorReplay: the sample's traces recorded and run through
// the model's predictor of kind `predictor_kind` (BranchPredictorConfig) as the microbenchmark
// times them (the TAGE: simulate_displaced_batch, for a back end of `width` lanes in the scene
// whose tree has leaves `node_leaf`; the unseen-ops predictor: none, the batch just run).
ModelledMispredictions replay_short_stream_predictor(const TraversalRecorder& others,
                                                     const TraversalRecorder& batch, uint32_t width,
                                                     const std::vector<uint8_t>& node_leaf,
                                                     const std::string& predictor_kind);
// The fitted one- and few-lane costs into each kind's OpCostConfig, and the box test's per-op
// cost where the traversals measured it (its stream loop's, in a traversal).
void set_short_stream_costs(const ShortStreamCosts& fit, std::vector<OpCostConfig>& costs);

// Describes the host, runs the microbenchmarks (each point repeated by `convergence`) and
// fits. `isa`: the back end measured (auto: the widest). `progress(done, total)` per op kind.
// `branch_model`: the BranchPredictorConfig kind fitted on the branch microbenchmark
// ("unseen_ops" or "tage"; sfx calibrate --branch-model).
// `memory_from` (a host file of this machine, read as `memory_source` names it), where given:
// its scene memory instead of measuring one (HostDescription::memory).
// The few-ray loop's costs as another wide back end's host file of the machine gives them
// (`sfx calibrate --describe-host --few-ray-from FILE`, HostDescription::few_ray_source): its
// box test's few-lane and entry costs and the loop's misprediction cost, and the short loops'
// (one-ray and few-ray: the same code at every width of k_few_ray_min_width lanes or more)
// exposed share of a node read (OpCostConfig::node_read_exposed_share).
struct FewRayFrom {
    GivenFewRayCosts costs;
    double mispredict_cycles = 0.0;
    std::string branch_model;  // the file's BranchPredictorConfig::kind, which prices it
    double node_read_exposed_share = 1.0;
    std::string source;  // the file
};
// Those of `file` (read from `source`) for a back end of `isa`. Throws std::invalid_argument
// where that back end has no few-ray loop or the file has no such costs.
FewRayFrom few_ray_costs_from(const HwConfig& file, const std::string& source, Isa isa);

// An op kind's fitted `cost` on its `samples` (the i-th with key `keys[i]`: its buffer's slots,
// or its stream's length): per key of `wanted`, the median of (priced - measured) / measured, a
// measurement under k_fit_resolution_cycles counting as that (NaN where none has that key).
std::vector<double> fit_residuals_by(const OpCostConfig& cost, uint32_t width,
                                     const std::vector<OpCostSample>& samples,
                                     const std::vector<uint32_t>& keys,
                                     const std::vector<uint32_t>& wanted);

HostCalibration calibrate_host(Isa isa, const ConvergenceRule& convergence,
                               const std::function<void(uint32_t, uint32_t)>& progress = {},
                               const HwConfig* memory_from = nullptr,
                               const std::string& memory_source = "",
                               const FewRayFrom* few_ray_from = nullptr,
                               const std::string& branch_model = "unseen_ops");

// Pins the calling thread (and threads it starts) to the CPU it runs on; false if refused.
bool pin_to_current_cpu();

struct SiliconMeasurement {
    uint64_t seed = 0;  // the measured frame's (predict_and_measure gives each workload its own)
    Prediction prediction;                     // the machine model's, whole
    std::array<double, 3> predicted_stage{};   // traversal, intersection, shading (cycles)
    std::array<double, 3> predicted_memory{};  // of which scene-data misses
    // The traversal by the tracer's loop that runs its box tests (TraversalLoop: one-ray,
    // few-ray, stream loop), predicted and measured (the stage clock's short-loop ticks,
    // RenderStats::short_loop_tsc, split as the stages are; the stream loop the rest).
    std::array<double, 3> predicted_loop{}, measured_loop{};
    // The intersection stage by the loop whose leaf code runs its tests (the loop of the box test
    // that reached the leaf), predicted (FrameTiming::intersection_loop_cycles) and measured
    // (RenderStats::short_loop_leaf_tsc, split as the stages are; the stream loop's the rest).
    std::array<double, 3> predicted_leaf_loop{}, measured_leaf_loop{};
    // The shading stage by op kind (shading kinds only), predicted (FrameTiming::op_cycles) and
    // measured (the stage clock's RenderStats::shading_op_tsc, the fewest ticks of each, split
    // as the stages are); and the tracer's ray set-up (load_rays), measured only: the model
    // prices it in the ops that made the rays.
    std::array<double, k_op_kind_count> predicted_shading_op{}, measured_shading_op{};
    double measured_ray_setup = 0.0;
    double predicted_frame = 0.0;
    // Core cycles (base/cycle_source.h: counted by perf_event_open, else the thread's CPU time
    // at the back end's clock measured before and after the render; the TSC alone counts the
    // neighbours' time on a shared machine, and the core's clock moves): the fastest of the
    // unclocked renders (the microbenchmarks take their fastest too), which counts only if
    // `convergence` says the fastest of them agree.
    double measured_frame = 0.0;
    // The frame as the sum of its parts' fastest (RenderStats::part_tsc: a pass's generations,
    // 2-20 a pass), each part over the unclocked renders whose clock held in which the monitor's
    // probes around it found the core alone (clean_spans, base/core_contention.h), kept or set
    // aside, plus the fastest rest of a render, in TSC ticks at the median cycles a tick of those
    // renders; judged by judge_parts_convergence (0: no render). A sibling thread's burst of
    // 1-10 ms slows the parts it falls in, not the frame's others: on a core shared a third of
    // the time a render of 50 ms seldom runs alone, while each of its parts of a few
    // milliseconds often does. It also takes each part's luckiest placement and cache state:
    // read over every render, clean or not, it lay 3-5 % under the fastest render on cornell and
    // furnace 64x64, which converged (AVX2, Zen 4, 2026-12-03).
    double measured_frame_parts = 0.0;
    Convergence parts_convergence;
    uint32_t frame_parts = 0;  // parts a render
    Convergence convergence;
    std::string cycle_source;  // CycleSource::description() of the back end's source
    bool cycles_counted = false;
    double clock_mhz_before = 0.0, clock_mhz_after = 0.0;  // around the fastest render
    // Placement: KiB of the process in transparent huge pages after each render, least and
    // most (-1: unreadable); every render's buffers land after a heap block of random size.
    int64_t huge_page_kib_min = -1, huge_page_kib_max = -1;
    // The other CPUs' busy share over its unclocked renders (base/cpu_load.h; -1: unknown): a
    // neighbour's load biases a whole run, and no convergence rule sees it.
    double neighbours_busy = -1.0;
    double measured_frame_tsc = 0.0;         // the raw TSC ticks' median, for comparison
    std::vector<double> frame_samples;       // every unclocked render's cycles
    // With memory_now, the L3 chased in each frame sample's round (kib, others' fills per us):
    // whether a render's time follows the L3 its neighbours left it.
    std::vector<uint32_t> frame_sample_l3_kib;
    std::vector<double> frame_sample_l3_fill_per_us;
    std::array<double, 3> measured_stage{};  // split of per-stage fewest ticks x measured_frame
    double stage_clock_overhead = 0.0;       // clocked render's cycles / unclocked median - 1
    uint32_t interrupted = 0;  // renders whose TSC ticks exceeded their CPU time by > 3 %
    // Unclocked renders set aside because the estimate's clock moved over them by more than
    // the convergence tolerance (clock_moved, base/cycle_source.h); not among frame_samples.
    uint32_t clock_moved = 0;
    // Renders over which (ContentionMonitor) or after which the core was found shared with
    // another hardware thread, set aside and taken again; at the budget's number the workload
    // stops (base/core_contention.h).
    uint32_t contended = 0;
    // Renders taken again before a measured one to warm the caches, one after each of the
    // gate's waits for the core, asleep 10 ms or more (CoreContention::wait_warm).
    uint32_t rewarmed = 0;
    // Every unclocked render, kept or set aside: its cycles and the share of the contention
    // monitor's probes during it that found the core shared (ContentionMonitor); and the
    // monitor's own time over the kept renders, as a share of them (subtracted from their cycles).
    std::vector<double> render_cycles, render_shared_share;
    double monitor_share = 0.0;
    // The machine's speed during the renders against calibration: the speed probe re-run just
    // before the first render and just after the last, over its cycles at calibration, less 1
    // (NaN: the host file has none). The same for every workload of a back end; a probe beyond
    // +-10 % flags a run slowed (or sped) alike.
    double probe_before = 0.0, probe_after = 0.0;
    // The L3 this core keeps (last_level_seen: its size and others' fills), chased just before
    // the first render and just after the last (kib 0: not chased). On a shared machine it
    // moves within a minute (22.3 to 4.5 MiB in four descriptions on this project's AMD VM,
    // 2026-11-28); a large move between the two flags a run whose memory was not the one
    // the renders began with. With `memory_now` it is also chased at the start of every round
    // (`l3_render`: the round of this workload's fastest render), and the model predicts every
    // workload with `l3_run`, the median over all workloads' kept renders of their rounds'
    // chases (median_level), in place of the host file's L3. One L3 for all: a chase takes
    // 2.3 s and reads 2x apart within seconds (6.2 to 11.7 MiB, this project's Zen 4 VM,
    // 2026-12-04), and a render's time barely follows its round's reading (Spearman -0.22 over
    // 621 renders): with each workload's own round, the model's tiles of one frame differed
    // by their readings (scalar temple 64x64: 31.5 / 36.2 / 29.0 Mcycles at 13.3 / 10.4 /
    // 18.9 MiB) more than by their tiles. The frames with the file's L3 and with the round's
    // are kept for comparison.
    SeenLevel l3_before, l3_after, l3_render, l3_run;
    uint32_t l3_rounds_kib_min = ~0u, l3_rounds_kib_max = 0;  // over the rounds' chases
    double predicted_frame_described = 0.0, predicted_frame_round = 0.0;
    // From cold caches (SiliconVariant::cold): the renders after evict_caches
    // (base/cache_eviction.h), which leaves none of the scene in this core's caches, under the same
    // rule; the prediction from empty caches. 0 and no samples where not asked for.
    double predicted_cold_frame = 0.0, measured_cold_frame = 0.0;
    Convergence cold_convergence;
    std::vector<double> cold_samples;
};

// The speed probe: microbenchmark points of a traversal, an intersection and two shading
// filters (box, triangle, emission, Lambertian indirect; streams of 512 and 1024 of 1024
// slots), their fastest cycles summed. Measured at calibration (HwConfig::speed_probe_cycles)
// and around a check's renders: their ratio says whether the machine runs as calibrated. The
// fastest of `probes` probes a second apart: a probe taken in a spell of the sibling hardware
// thread (base/core_contention.h) converges there, and a spell slows a probe, never speeds it.
// On the Zen 4 VM (2026-12-03) single probes before a check's renders read +36.5 / +28.0 /
// +10.9 % (scalar / AVX2 / AVX-512) and after them +0.1 / -0.5 / -0.3 %, on host files
// calibrated 15 minutes before; a run so flagged was calibrated and checked again.
double speed_probe_cycles(Isa isa, const ConvergenceRule& convergence, uint32_t probes = 3);
// The probe's `cycles` now against `reference` (at calibration): +0.1 is 10 % slower; NaN
// without a reference. Beyond k_speed_probe_tolerance either way the machine is not the one
// measured then (scripts/silicon-check calibrates again).
double speed_probe_drift(double cycles, double reference);
constexpr double k_speed_probe_tolerance = 0.10;
// The fastest cycles of the speed probe's points among `samples` (a calibration's sweeps, which
// time every kind at those buffers and lengths too), summed as the probe sums its own.
double speed_probe_points_cycles(const std::vector<MicrobenchSample>& samples);
// How far a calibration's machine moved: the larger in size of the probe's drift from before
// the microbenchmarks to after, and of the sweeps' timing of the probe's points from the probe
// after (NaN where neither was measured). Beyond k_speed_probe_tolerance, calibrate again.
double calibration_drift(const HostCalibration& c);

// One workload of a silicon check: its scene, render settings and the host configuration (whose
// SIMD width is the back end's, settings.isa) that predicts it.
struct SiliconVariant {
    const Scene* scene = nullptr;
    const Bvh* bvh = nullptr;
    RenderSettings settings;
    const HwConfig* host = nullptr;
    // Also measured and predicted from cold caches: what a frame pays for the scene lines the
    // render before left (the model's misses to DRAM, and the lines' ageing, on silicon).
    bool cold = false;
};

// The frames a check's workloads render and the order its rounds take them in. Workloads of one
// scene, resolution, sample count, depth and seed render the same frames (`frames`: their group's
// index; seeds k_frames_per_workload apart per group), so that a cell's tiles and back ends are
// compared on the same work: with frames of each workload's own (until 2026-12-07), a pair's
// predicted difference moved with the frames (scalar furnace 64x64, tile 64 over 16: -1.2, -2.0
// and +1.0 % for three pairs of seeds, on an Intel Xeon VM) as far as the pairs the rankings
// ordered wrong were measured apart (0.4-2.3 %). A round takes each group's first workload, then
// each one's second, and so on (`rounds`), so that between two renders of one frame come the
// other groups' renders: a render right after its own frame finds what the model's warm frames do
// not hold (below).
struct SiliconOrder {
    std::vector<uint32_t> frames;  // per workload: its frame group
    std::vector<size_t> rounds;    // the workloads in the order a round renders them
};
SiliconOrder silicon_order(const std::vector<SiliconVariant>& variants);

// Which of a workload's other frames (other_frame in kernels/render.h) the check renders where
// it does not time the workload's own: none of its timed renders follows a render of the same
// frame, whose random outcomes the core's branch predictor would have learned (the model prices
// them fresh). Its measured render follows the warm frame and the stage-clocked one (whose
// stage shares stand for the measured frame's: another seed moves them by its noise only), as
// the model's warm frames (sampling's: other_frame 2, then 1) precede its timed one; its cold
// render, after the measured one, is a frame of its own, predicted as such. A frame group's
// workloads are rendered apart (SiliconOrder): rendered one after another, the workloads before
// it (the same scene at other tiles and back ends) left the caches lines of its own frame, which
// the model's warm frames do not hold (atrium's and conference's AVX2 frames measured 0-6 %
// slower after two other frames than after their own, 2026-12-05, where the model warmed by those
// two put them 1-9 % dearer); a check of one scene and resolution has nothing to put between.
constexpr uint64_t k_clocked_frame = 1, k_warm_frame = 2, k_cold_frame = 3;
// Its own frame and its other frames 1 to k_cold_frame.
constexpr uint64_t k_frames_per_workload = k_cold_frame + 1;

// The check has its ray buffers allocated anew in each round, by the warming render before the
// measured one (release_kept_ray_buffers, kernels/stream/stream_tracer.h; made by every render
// until 2026-12-05), and glibc serves a block beyond its mmap threshold from a fresh mapping and
// returns a freed heap top beyond its trim threshold to the kernel, both thresholds moving as the
// process frees: whether a render's buffers come back as pages already faulted in follows the
// process's allocation history, an effect that holds for a whole run. On an AMD Zen 5 VM
// (2026-12-05, AVX2) cornell 64x64 rendered alone in a process faulted 244 pages a render at tile
// 64 and took 4.8-5.5 ms of CPU time a render, 1.1 ms with both thresholds raised (tile 32: 1.7 and
// 1.1 ms; 128x128 at tile 64: 356 pages, 9.1-9.3 ms against 4.6-4.7). This keeps freed memory in
// the heap for the rest of the process: predict_and_measure calls it first, so that a frame's
// cycles hold no page zeroing (a renderer keeps its buffers).
void keep_freed_memory_in_heap();

// The workloads of a check (scenes, resolutions, tiles, back ends), each forced to one thread;
// every host config must carry op_costs for every kind its scene uses. Each is predicted by the
// machine model on the trace of its own render (before the renders; with `memory_now`, after
// them); rounds render every workload that has not
// converged in turn (trace off), once plain and once with the stage clock, until each has
// converged or spent its budget (`convergence`): every workload's renders span the whole run,
// so that the drift of a shared machine touches all of them alike, and a slow spell shows as
// disagreement instead of a bias. Each measured render follows an unmeasured render of its own
// workload (other frames, above), so that it starts from the caches predict() assumes. A workload
// asked for `cold` also renders, each round, after evicting this core's caches. `seed` draws the
// heap offsets that vary placement. `progress(what, done, total)` as it goes. With `memory_now`,
// the L3 is chased at the start of every round, and every workload is predicted after the renders
// with the median of the chases the kept renders met as its host's last cache level
// (SiliconMeasurement::l3_run), not the file's: the check then predicts the memory its
// renders met.
std::vector<SiliconMeasurement> predict_and_measure(
    const std::vector<SiliconVariant>& variants, const ConvergenceRule& convergence,
    uint64_t seed = 1, const std::function<void(const std::string&, size_t, size_t)>& progress = {},
    bool memory_now = false);

// The L3 this core keeps now: the last level's chases (chase_last_level) on this machine's
// caches, read by last_level_seen (kib 0 where the CPU reports fewer than two levels).
SeenLevel chase_last_level_now(double tsc_mhz);

// The median level of `levels` (size and others' fills, each its own median, over those
// chased; kib 0 where none was).
SeenLevel median_level(const std::vector<SeenLevel>& levels);

// `host` with its last scene-memory level's size and others' fills as `seen` says (unchanged
// where `seen` was not chased or the host has no shared last level).
HwConfig with_last_level(const HwConfig& host, const SeenLevel& seen);

}  // namespace sfx
