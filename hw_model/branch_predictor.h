#pragma once
// A CPU core's conditional-branch predictor, and the branches the native tracer's traversal
// takes, derived from the trace. Fitted op costs come from microbenchmarks that repeat the same
// ops, whose branches a predictor learns; a frame's traversals never repeat, and on a real
// scene's tree their outcomes follow no pattern a predictor has seen (silicon: the page's
// "branch predictor" section). The model runs its own predictor over the frame's branches and
// prices each misprediction.
//
// The predictor is TAGE (Seznec & Michaud, "A case for (partially) TAgged GEometric history
// length branch prediction", JILP 8, 2006) in L-TAGE's geometry (Seznec, CBP-2 2006; gem5's
// LTAGE_TAGE: a 16 K-entry bimodal base, 12 tagged tables of 512-2048 entries with tags of 7-15
// bits, global histories 4 to 640 branches, 3-bit counters, 2-bit useful counters), without
// its loop predictor. A modern core's predictor is of this family; its exact design is not
// published.

#include <array>
#include <cstdint>
#include <memory>
#include <vector>

#include "hw_model/pass_buffer.h"
#include "kernels/trace.h"

namespace sfx {

class TagePredictor {
  public:
    TagePredictor();
    // Predicts the branch at `pc`, learns its outcome; returns whether it mispredicted.
    bool predict_and_update(uint32_t pc, bool taken);
    // A counted loop of the stream loop run `trips` times: its test after each trip but the
    // first, taken until the last, through a TAGE of its own whose history holds the stream
    // loop's counted loops' tests alone (the box filter's group loop, for_each_group, whose
    // first test is the replay's one branch an op in the global history, "a second group?";
    // the copy of the failing ids, copy_ids: kernels/stream/stream_kernels_impl.h), so that the
    // global history, and the short loops' predictions with it, does not follow the width.
    // Trip counts that repeat (a microbenchmark's batch timed right after itself) have their
    // exits learned; a frame's op lengths do not repeat, and each exit is mispredicted about
    // once an op. Returns its mispredictions, which mispredictions() counts too.
    uint32_t run_counted_loop(uint32_t pc, uint32_t trips);
    uint64_t branches() const { return m_branches; }
    uint64_t mispredictions() const { return m_mispredictions; }
    // Of branches(), the counted loops' tests (run_counted_loop).
    uint64_t counted_loop_branches() const { return m_counted_loop_branches; }

  private:
    static constexpr int k_tables = 12;
    struct Entry {
        int8_t ctr = 0;  // 3-bit signed: taken when >= 0
        uint16_t tag = 0;
        uint8_t u = 0;  // 2-bit useful counter
    };
    // A history of `length` bits folded into `bits` bits, updated a bit at a time (Michaud,
    // "A PPM-like, tag-based branch predictor", JILP 7, 2005).
    struct Folded {
        uint32_t value = 0, length = 0, bits = 1;
        void update(uint8_t newest, uint8_t oldest);
    };
    uint32_t index(int t, uint32_t pc) const;
    uint16_t tag(int t, uint32_t pc) const;
    void push_history(bool taken);

    std::vector<int8_t> m_base;  // 2-bit counters: taken when >= 0
    std::array<std::vector<Entry>, k_tables> m_table;
    std::array<uint32_t, k_tables> m_history_length{}, m_log_size{}, m_tag_bits{};
    std::array<Folded, k_tables> m_fold_index, m_fold_tag0, m_fold_tag1;
    std::vector<uint8_t> m_history;  // circular global history, newest at m_head
    uint32_t m_head = 0;
    int m_use_alt_on_new = 0;  // 4-bit signed: trust the alternative over a fresh entry
    uint64_t m_branches = 0, m_mispredictions = 0;
    uint32_t m_seed = 0x2545f491;  // allocation's pseudo-random choice
    std::unique_ptr<TagePredictor> m_counted_loops;  // run_counted_loop's, made on its first use
    uint64_t m_counted_loop_branches = 0;
};

// The box tests of a pass by the native tracer's loop that runs them (TraversalLoop): the
// stream loop's child streams of one ray run in the one-ray loop and of 2 to k_few_ray_lanes in
// the few-ray loop (wide back ends), and every op below stays in that loop; an intersection op
// by the loop of the box test that reached its leaf (its producer), whose leaf code runs it.
// Other ops: stream.
std::vector<TraversalLoop> traversal_loops(const PassBuffer& pass, uint32_t width);

// The traversal's data-dependent conditional branches, op by op in the trace's order (the
// tracer's program order), through `predictor`: per box test the loop's test of its stream
// length (stream loop: one ray? few?), whether any lane passed (the one-ray loop: the ray), and
// whether a node is a leaf (the prefetch of what it needs next, before the test; and after a
// pass); the stream loop's group loop (one branch an op: a second group?; its further tests
// and the loop copying the failing ids, run_counted_loop); the one-ray loop's
// stack; per leaf test whether a lane took the hit and whether another primitive follows.
// `node_leaf[node]`: the tree's leaves (the trace names the nodes tested, not their kind).
// `mispredicted[i]` gets op i's count.
void replay_traversal_branches(const PassBuffer& pass, const std::vector<TraversalLoop>& loops,
                               uint32_t width, const std::vector<uint8_t>& node_leaf,
                               TagePredictor& predictor, std::vector<uint32_t>& mispredicted);

// The model's side of the predictor microbenchmark (kernels/stream/stream_microbench.h): a
// fresh predictor warmed by every batch in turn; then each batch's mispredictions right after
// itself (primed: the fewest of at least `repetitions` samples of two runs, more while the
// fewest still falls) and right after the other batches (displaced: the fewest of
// `repetitions`), as the microbenchmark keeps the fastest sample; summed over the batches.
struct PredictorStates {
    uint64_t primed = 0, displaced = 0;
    // Of those, the box tests' by the loop that runs them (TraversalLoop: one-ray, few-ray,
    // stream), as the model prices them in FrameTiming::traversal_loop_branch_cycles.
    std::array<uint64_t, 3> primed_by_loop{}, displaced_by_loop{};
    uint64_t branches = 0;  // one pass over the batches
};
PredictorStates simulate_predictor_states(const std::vector<const PassBuffer*>& batches,
                                          uint32_t width, const std::vector<uint8_t>& node_leaf,
                                          uint32_t repetitions = 5);

// The unseen-ops predictor (BranchPredictorConfig kind "unseen_ops"): one that learns a
// traversal only from the same traversal just run, nothing from other rays' traversals, so
// that each op of a traversal it has not just run (a box test, priced by its loop; a leaf test,
// `is_traversal_op`) counts one misprediction. On the branch microbenchmark (an Intel Xeon VM,
// 2026-12-06) what the core's displaced batches took beyond their cached state followed the
// batches' box tests (residual 8.8 K cycles rms over 96 batches at 36-41 cycles a box test,
// AVX2) and not the TAGE's added mispredictions (22.6 K rms at 110 cycles each): a TAGE whose
// history holds the traversal's data-dependent branches alone learns random rays' traversals
// from one another, the core's does not. Primed (the batch just run): none; displaced: every
// traversal op, summed over `batches` as simulate_predictor_states sums its states.
bool is_traversal_op(OpKind kind);
PredictorStates unseen_ops_states(const std::vector<const PassBuffer*>& batches, uint32_t width);

// The model's side of a short-stream microbenchmark sample (run_one_ray_microbenchmarks,
// kernels/stream/stream_microbench.h): a fresh predictor over the other rays' traversals
// (twice, the first warming it), then over the batch's; the batch's mispredictions (with
// `box_by_loop`, its box tests' by the loop that runs them, as PredictorStates has them).
uint64_t simulate_displaced_batch(const PassBuffer& others, const PassBuffer& batch, uint32_t width,
                                  const std::vector<uint8_t>& node_leaf,
                                  std::array<uint64_t, 3>* box_by_loop = nullptr);

// BranchPredictorConfig::mispredict_cycles from the branch microbenchmark: what the displaced
// batches took beyond the cached ones (the predictor's part, measured) over the mispredictions
// the model adds from primed to displaced, pooled over the samples (0 where it adds none).
double fit_mispredict_cycles(const std::vector<double>& extra_cycles,
                             const std::vector<double>& extra_mispredictions);

}  // namespace sfx
