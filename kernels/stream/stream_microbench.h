#pragma once
// Microbenchmarks of the stream tracer's native filters on synthetic streams: each op kind's filter
// (the box kernel; the triangle and sphere tests by the traversal's own leaf code,
// StreamKernels::leaf_tests, on a leaf of one primitive; the camera and every shading filter of
// Fig. 4 with the same per-ray steps of path.h) run with the trace off on streams of a chosen
// length whose ids are a random subset, in increasing order (as the tracer's stable partitions keep
// them), of a ray buffer of a chosen size, against a small synthetic scene (a floor, a glossy
// panel, a glass sphere, a light: no shipped scene). Time is the time-stamp counter around one
// call, the fastest of repetitions that go on until their fastest k agree or a budget runs out
// (base/convergence.h: a shared machine only ever adds time), in core cycles (the TSC over
// base/core_clock.h's ticks per core cycle of the back end's own chain, taken just before). A
// traversal op (box, triangle and sphere tests) is timed right after one call of itself on a
// few lanes of a small buffer of its own, so that it finds its code warm, as a frame's back-to-
// back traversal ops do; a shading filter, which a frame runs once a generation between the
// others, is timed cold, right after a traversal of other rays, which leaves the core's clock
// as a frame's traversal leaves it for the shading stage (AVX-512's is lower). An op is timed with
// all the per-ray work the tracer does for it: the emission filter computes the hits' surfaces
// (surface_at), and the rays that the camera and every shader make are set up for the next
// generation's traversal (set_up_ray, the tracer's load_rays) in a loop of their own after the
// op's calls, as the tracer sets them up (set up in the loop that made it, a pinhole camera's ray
// cost 131 cycles on a Zen 5 core at AVX2, against 78 for the frame's camera loop and set-up
// together, 2026-12-01). `sfx calibrate --describe-host` fits
// the host's per-op costs to these samples (hw_model/op_cost_fit.h), never to frames.

#include <algorithm>
#include <array>
#include <cstdint>
#include <functional>
#include <vector>

#include "base/convergence.h"
#include "kernels/simd/isa.h"
#include "kernels/trace.h"

namespace sfx {

class Bvh;
struct Scene;

// Bytes of the stream tracer's ray buffers per slot (every per-slot array of a pass): what a
// pass of n slots asks the L1D to hold.
uint32_t stream_slot_bytes();
// The arrays those bytes beyond the traversal record lie in that a slot indexes: path state,
// the two ray generations, the full tests' constants, hit, any-hit flag and surface (the id
// lists and the mask are indexed by stream position, which ascends: RayBufferConfig::
// slot_arrays).
uint32_t stream_slot_arrays();
// Bytes per slot of the arrays a microbenchmark repetition over a buffer of `slots` slots asks
// the caches to hold (its timed calls, their made rays' set-up and the touch before them): the
// fit prices its points as if they were stream_slot_bytes.
double microbench_timed_slot_bytes(uint32_t slots);

struct MicrobenchSample {
    OpKind kind = OpKind::box_test;
    uint32_t slots = 0;   // the ray buffer the stream's ids are scattered over
    uint32_t lanes = 0;   // stream length
    uint32_t passed = 0;  // lanes that passed (the filter's result)
    double cycles = 0.0;  // core cycles per call (base/core_clock.h), fastest repetition
    bool converged = false;  // its fastest repetitions agreed (base/convergence.h)
    uint32_t repetitions = 0;
    bool thin_lens = false;  // the camera's: timed on a thin-lens camera, not the pinhole
    bool sphere_light = false;  // the direct-light filter's: timed on a sphere light, not the quad
    // The triangle test's: timed on candidates that fail (OpCostConfig::
    // per_failed_candidate_cycles).
    bool failing_candidates = false;
    // The triangle test's: lanes the float stage did not reject that failed the full test
    // (StreamOp::failed_candidates), counted by the tracer's own float stage on the timed streams.
    uint32_t failed_candidates = 0;
    // The emission filter's: timed on hits on spheres; its plain samples on hits on triangles
    // (OpCostConfig::sphere_hit_per_lane_cycles).
    bool sphere_hits = false;
    // A shading op's: what its call costs cold, as a frame's calls are, over the same call
    // warm (MicrobenchOptions::cold_call_lengths); timed where cold_call_timed.
    double cold_call_cycles = 0.0;
    bool cold_call_timed = false;
    // A variant's samples price only its extra over the plain op (fit_extra_per_passing_lane,
    // fit_extra_per_failed_candidate, fit_extra_per_lane).
    bool variant() const { return thin_lens || sphere_light || failing_candidates || sphere_hits; }
};

// The microbenchmarks' default rule: the fastest 3 within 3 %, 5 to 9 repetitions.
inline ConvergenceRule microbench_rule(uint32_t budget = 9) {
    ConvergenceRule r;
    r.fastest = std::min<uint32_t>(3, budget);
    r.tolerance = 0.03;
    r.min_samples = std::min<uint32_t>(5, budget);
    r.budget = budget;
    return r;
}

struct MicrobenchOptions {
    Isa isa = Isa::automatic;
    // 8^2 (inside a 32 KiB L1D: what tells the per-lane cost from the cost beyond the L1D),
    // 16^2, 32^2 and 64^2 ray buffers.
    std::vector<uint32_t> buffer_slots = {64, 256, 1024, 4096};
    std::vector<uint32_t> lengths = {1, 8, 16, 24, 48, 96, 200, 512, 1024, 4096};
    ConvergenceRule convergence = microbench_rule();  // repetitions per point and visit
    // A point's repetitions come from this many sweeps over every point (each sweep's until
    // `convergence` holds; the point's fastest judged over all of them), so that one spell of
    // a slow machine cannot take all of a point's repetitions: on an Intel VM (2026-11-28) a
    // spell of tens of milliseconds at a third of the speed took every repetition of a run of
    // neighbouring points, whose fastest three then agreed (a 16-lane box test 294 cycles in
    // one sweep, 93 in others).
    uint32_t visits = 2;
    uint64_t seed = 1;
    std::vector<OpKind> kinds;  // empty: every kind the native tracer has
    // A frame calls each shading filter once per generation of a tile, the tile's traversal
    // and the other filters between two calls, where the points above call it `inner` times
    // back to back (the TSC steps by tens of cycles). So a shading op's mixed points of these
    // lengths on the buffer of cold_call_slots also time pairs of single calls: the first
    // right after a pass of a 16 x 16 tile of the synthetic scene through the stream tracer
    // (and a touch of the buffer: its rays are where the previous filter left them), the
    // second right after it on other rays of the same mix (OpCostConfig::cold_call_cycles).
    std::vector<uint32_t> cold_call_lengths = {8, 24, 96};
    uint32_t cold_call_slots = 256;
    uint32_t cold_call_pairs = 512;
};

// Whether a frame's streams of `kind` hold only hits that are not shadow rays: the tracer's
// shading stack runs it after its shadow and miss filters (kernels/stream/stream_tracer.cpp).
// Its microbenchmark streams hold the same, dealt from the buffer's hits: a lane without a hit
// leaves such a filter at its first test, and the buffer's misses (a third of its rays) made
// the lambertian and scattering filters' failing lanes nearly all misses, which no frame has
// (an Intel Xeon VM, 2026-11-29: lambertian_direct's 1411 failing rays of 4096, 1252 of them
// misses; fitted so, its frames were priced 20-25 % under on atrium and temple).
bool frame_streams_hold_hits_only(OpKind kind);

// A traversal's start cold, as a frame's are (a tile's filters between two), over one right
// after another: per length of `lengths`, the mean over `pairs` pairs of traversals of that
// many rays of the synthetic scene from the root (StreamKernels::traverse, trace off), the
// first right after a pass of a 16 x 16 tile, the second right after it on other rays
// (cold_call_difference), in core cycles (OpCostConfig::cold_call_cycles of the box test).
std::vector<double> run_cold_traversal_microbenchmarks(Isa isa,
                                                       const std::vector<uint32_t>& lengths,
                                                       uint32_t pairs);

// A cold call's cost over a warm one from pairs of single calls (MicrobenchOptions::
// cold_call_lengths), in the samples' unit: the mean difference over the pairs neither of
// whose calls took over four times its median (an interrupt); 0 without pairs.
double cold_call_difference(const std::vector<double>& cold, const std::vector<double>& warm);

// Every op kind the native tracer has, at every (buffer, length <= buffer; a hits-only kind's
// mixed streams no longer than its hits can fill). `progress(done, total)` is called after
// each kind.
std::vector<MicrobenchSample> run_stream_microbenchmarks(
    const MicrobenchOptions& options, const std::function<void(uint32_t, uint32_t)>& progress = {});

// Traversals: StreamKernels::traverse (trace off) of one-ray streams, of streams of 2 to
// k_few_ray_lanes rays (kernels/trace.h) and of longer ones, from the root, one after another, in
// the synthetic scene with its floor cut into 16 x 16 quads and 16 small spheres on it (so a
// traversal tests as many boxes as a secondary ray's short-stream subtree does, and spheres
// often enough to fit their cost). Every op of a one-ray stream has one lane and runs in the
// one-ray loop (traverse_one), whatever the width; a few-ray stream's box tests run in the
// few-ray loop on a back end of k_few_ray_min_width lanes or more (the stream loop otherwise),
// its leaves' tests in the stream loop's leaf code, and its one-ray subtrees in the one-ray loop;
// a longer stream's box tests run in the stream loop until its streams narrow to those.
struct OpsOfLength {
    OpKind kind = OpKind::box_test;
    uint32_t lanes = 0;
    uint64_t count = 0, passed = 0;  // ops, and passing lanes summed over them
    uint64_t failed_candidates = 0;  // summed over them (StreamOp::failed_candidates)
};
struct OneRaySample {
    uint32_t rays = 0;         // per stream
    uint32_t streams = 0;      // traversed one after another
    uint32_t slots = 0;        // of the ray buffer the batch's rays occupy (its footprint)
    // Where each stream enters the tree: the root (0), or the node this many levels down its
    // first ray's way (a frame's short streams start deep: a one-ray subtree of atrium, 64 x 64,
    // tile 16, holds 4.9 box tests, a ray from the root 15 in this scene).
    uint32_t entry_depth = 0;
    // The one-ray and few-ray loops the traversals entered from the stream loop (a stream of one
    // to k_few_ray_lanes rays enters one at once): what costs a loop's start (ShortLoopClock).
    std::array<uint64_t, 2> entries{};
    // Counted by the same traversals: per kind, its one-lane ops (the one-ray loop's) and its
    // few-ray loop's ops (box tests of 2 to k_few_ray_lanes lanes on a wide back end); every
    // other op by kind and length (priced by the stream formula).
    std::array<uint64_t, k_op_kind_count> ops{};
    // The one-lane ops' passing lanes and failed candidates (one_lane_pass_cycles,
    // one_lane_failed_candidate_cycles).
    std::array<uint64_t, k_op_kind_count> one_lane_passed{}, one_lane_failed_candidates{};
    std::array<uint64_t, k_op_kind_count> few_ops{};
    std::vector<OpsOfLength> stream_ops;
    // Lanes of the traversals whose rays share one origin (StreamOp::origin_shared: a bundle's)
    // after each one's first, which the tracer's check of that compared with the first
    // (OpCostConfig::shared_origin_per_lane_cycles).
    uint64_t origin_shared_lanes = 0;
    double cycles = 0.0;  // core cycles, fastest repetition
    bool converged = false;
    uint32_t repetitions = 0;
    // The mispredictions the model's branch predictor makes on the batch's traversals, run as
    // the timed repetitions run them (`predictor_replay` below; 0 without one), and of those
    // the box tests' by the loop that runs them (TraversalLoop: one-ray, few-ray, stream).
    double modelled_mispredictions = 0.0;
    std::array<double, 3> modelled_box_loop_mispredictions{};
    // Of the one-lane box tests (`ops`), those below a stream of 2 to k_few_ray_lanes rays: the
    // few-ray loop runs their one-ray subtrees itself, and the stage clock counts them there.
    uint64_t few_ray_one_lane_box_ops = 0;
    // Where a repetition's time went, by the stage clock a frame's traversal is split with
    // (TraversalJob::leaf_tsc, ShortLoopClock): the shares of the leaves and of the one-ray and
    // few-ray loops less their leaves (the median of 5 repetitions, each displaced as the timed
    // ones are; the clock's reads are in them). The short-stream fit takes the leaves off by
    // their share (OneLaneSample::leaf_cycles_clocked); the loops' shares are reported.
    double leaf_share = 0.0;
    std::array<double, 2> short_loop_share{};
};
// Traces a run of traversals into `sink` (TraceDetail::lanes, one TilePass of the sample's
// 4096 slots).
using TraversalRecorder = std::function<void(TraceSink& sink)>;
// The model's mispredictions on a batch: all, and the box tests' by loop (OneRaySample).
struct ModelledMispredictions {
    double total = 0.0;
    std::array<double, 3> box_by_loop{};
    uint64_t few_ray_one_lane_box_ops = 0;  // OneRaySample's, read off the same trace
};
// Given one sample's two recorders, what precedes each timed repetition (the other rays'
// traversals, then the batch's own) and the batch's traversals, returns the mispredictions the
// model's branch predictor makes on the batch after them (OneRaySample::modelled_mispredictions).
using PredictorReplay = std::function<ModelledMispredictions(const TraversalRecorder& others,
                                                             const TraversalRecorder& batch)>;
// Batches of 8 to 32 one-ray streams; on a back end of k_few_ray_min_width lanes or more, of 4 to
// 32 streams of 2, 3 and 4 rays; the same streams entering 3 and 6 levels down (8 and 32 of
// them); and of 1 and 4 streams of 8 to 128 rays, whose first ops run in the stream loop
// (several batches of each shape), drawn from 4096 rays; before
// each repetition of a batch the other rays are traversed in a new order, then the batch once
// untimed: the timed repetition is primed, where the model's predictor and the core's both
// mispredict little (the costs fitted on it hold the work; a frame's mispredictions are priced
// apart).
std::vector<OneRaySample> run_one_ray_microbenchmarks(
    Isa isa, const ConvergenceRule& convergence = microbench_rule(), uint64_t seed = 1,
    const PredictorReplay& predictor_replay = {});
// Their scene: the synthetic scene with its floor cut into 16 x 16 quads and 16 spheres.
Scene one_ray_microbench_scene();

// The field-read and compress rates by themselves: TSC ticks per lane of the box kernel's read
// of 7 fields for `lanes` ids over `slots` records (contiguous or random slots) with a box every
// ray passes, and of the compress partition (the median of `repeats`: reported, not fitted).
struct KernelRate {
    const char* what;
    uint32_t slots, lanes;
    bool scattered;
    double cycles_per_lane;
};
std::vector<KernelRate> run_gather_compress_microbenchmarks(Isa isa, uint32_t repeats = 9);

// The hits' surfaces read from scene arrays beyond the caches: the stream tracer's own loop
// (compute_surfaces, kernels/intersect.h, with its prefetches) over a stream of `lanes` hits
// on triangles drawn at random from a mesh of `triangles` (each with its own three vertices, in
// triangle order: 52 bytes of triangle record and vertices each), against the same loop on a
// cache-resident mesh of 64 triangles. What the first costs beyond the second is the latency
// of those reads that the core does not overlap; `sfx calibrate --describe-host` fits the share
// of the cache model's latency that this is (hw_model/op_cost_fit.h), never on frames.
struct SurfaceReadSample {
    uint32_t triangles = 0, lanes = 0;
    double cycles = 0.0;           // per stream, fastest repetition
    double resident_cycles = 0.0;  // the same stream length on the resident mesh
    bool converged = false;        // both agreed (base/convergence.h)
    uint32_t repetitions = 0;
    uint64_t seed = 0;  // of the hits' draw (surface_read_hits replays it)
};
// The tracer's check that a traversal's rays share one origin (shared_origin), timed over the
// records of a tile's camera rays that all do (1024 and 4096 slots, in order, as a 32- and a
// 64-pixel tile's): core cycles a lane, the slope between the two (a call's fixed cost is the
// traversal's start), each the fastest repetition of the convergence rule.
struct SharedOriginSample {
    double per_lane_cycles = 0.0;
    bool converged = false;
    uint32_t repetitions = 0;
};
SharedOriginSample run_shared_origin_microbenchmark(
    Isa isa, const ConvergenceRule& convergence = microbench_rule());
// Meshes of 2^13, 2^17 and 2^20 triangles (416 KiB, 6.5 MiB, 52 MiB), streams of 4096 hits.
std::vector<SurfaceReadSample> run_surface_read_microbenchmarks(
    Isa isa, const ConvergenceRule& convergence, uint64_t seed = 5);
// The triangles hit by repetition `repetition` of a sample's stream, in stream order.
std::vector<uint32_t> surface_read_hits(const SurfaceReadSample& sample, uint32_t repetition);

// What the branch predictor saves a traversal it has just run, in a given scene: the batches
// of a 64 x 64 frame's 16 x 16 tiles (their camera rays, and a bounce of each in a random
// direction from its hit, the hemisphere toward the camera), one stream each, through
// StreamKernels::traverse (trace off). Each batch is timed (the fastest repetition, until it
// converges) in three states: right after itself (primed); right after itself and a read of
// the scene lines that the other tiles' batches of its kind touch (primed, their lines
// cached: what a frame's caches hold); and right after those batches' traversals (displaced:
// a frame's traversals never repeat, so its predictor has seen other ones). Displaced over
// lines cached is the predictor's part; lines cached over primed, the caches'. A fourth state,
// right after itself and evict_caches (base/cache_eviction.h; evicted: every line in DRAM, the
// predictor primed), over primed is what reading the scene from DRAM costs. The per-op costs
// come from the synthetic scene's traversals (run_one_ray_microbenchmarks, displaced too); a
// scene whose branches are harder to predict pays more than they say, which the model prices
// by running its own predictor over the same batches (hw_model/branch_predictor.h).
// `batch_sink`, where given, receives each batch's trace (TraceDetail::lanes: one TilePass of
// 2 x 64 x 64 slots per batch, camera batches first) for the model to replay. Without
// `time_evicted` the evicted state is not timed (its cycles 0).
using PredictorBatchSink = std::function<TraceSink*(bool bounce, uint32_t batch)>;
// A state's cycles, summed over the batches, and their split as the stage clock splits a
// frame's traversal and intersection: the box tests by the loop that ran them (one-ray, few-ray,
// stream), and the leaves' tests by the loop whose leaf code ran them (that of their leaf's box
// test).
struct BatchStateCycles {
    double cycles = 0.0;
    std::array<double, 3> loops{}, leaves{};
};
struct PredictorSample {
    bool bounce = false;                // camera rays, or a bounce of each
    uint32_t batches = 0;               // tiles
    uint64_t box_tests = 0, lines = 0;  // summed over the batches (lines: each one's distinct)
    BatchStateCycles primed, cached, displaced, evicted;
    uint32_t converged_batches = 0;  // in every state timed (base/convergence.h)
};
// Untimed repetitions of a batch's state before its timed ones: the state before it outlasts
// one preparation (two: a displaced repetition after one was still the fastest in some batches).
constexpr uint32_t k_predictor_warm_repetitions = 2;
std::vector<PredictorSample> run_predictor_microbenchmarks(
    const Scene& scene, const Bvh& bvh, Isa isa, const ConvergenceRule& convergence,
    uint64_t seed = 3, const PredictorBatchSink& batch_sink = {}, bool time_evicted = true);
// The same in the synthetic scene whose traversals the per-op costs are fitted on (the floor of
// 16 x 16 quads and 16 spheres of run_one_ray_microbenchmarks): what those costs hold of it.
std::vector<PredictorSample> run_predictor_microbenchmarks(Isa isa,
                                                           const ConvergenceRule& convergence,
                                                           uint64_t seed = 3);
// The branch microbenchmark's scene, on which the cost of a misprediction is fitted (sfx
// calibrate --describe-host): 20,000 small triangles at random in a box, whose traversals no
// predictor learns from others.
Scene branch_microbench_scene();

}  // namespace sfx
