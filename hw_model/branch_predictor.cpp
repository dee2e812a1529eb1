#include "hw_model/branch_predictor.h"

#include <algorithm>
#include <cmath>

namespace sfx {

namespace {

// L-TAGE's tagged tables (gem5 LTAGE_TAGE: logTagTableSizes, tagTableTagWidths; minHist 4,
// maxHist 640).
constexpr std::array<uint32_t, 12> k_log_sizes = {10, 10, 11, 11, 11, 11, 10, 10, 10, 10, 9, 9};
constexpr std::array<uint32_t, 12> k_tag_bits = {7, 7, 8, 8, 9, 10, 11, 12, 12, 13, 14, 15};
constexpr uint32_t k_min_history = 4, k_max_history = 640;
constexpr uint32_t k_log_base = 14;                            // the bimodal base's entries
constexpr uint32_t k_history_slots = 1024;                     // > k_max_history, a power of two
constexpr uint64_t k_useful_reset_period = uint64_t(1) << 19;  // gem5 LTAGE logUResetPeriod

}  // namespace

void TagePredictor::Folded::update(uint8_t newest, uint8_t oldest) {
    value = (value << 1) | newest;
    value ^= uint32_t(oldest) << (length % bits);
    value ^= value >> bits;
    value &= (1u << bits) - 1;
}

TagePredictor::TagePredictor() : m_base(size_t(1) << k_log_base, 0), m_history(k_history_slots, 0) {
    for (int t = 0; t < k_tables; ++t) {
        // Geometric: L(t) = min * (max / min)^(t / (tables - 1)).
        m_history_length[t] =
            uint32_t(std::lround(k_min_history * std::pow(double(k_max_history) / k_min_history,
                                                          double(t) / (k_tables - 1))));
        m_log_size[t] = k_log_sizes[t];
        m_tag_bits[t] = k_tag_bits[t];
        m_table[t].assign(size_t(1) << m_log_size[t], Entry{});
        m_fold_index[t] = {0, m_history_length[t], m_log_size[t]};
        m_fold_tag0[t] = {0, m_history_length[t], m_tag_bits[t]};
        m_fold_tag1[t] = {0, m_history_length[t], m_tag_bits[t] - 1};
    }
}

uint32_t TagePredictor::index(int t, uint32_t pc) const {
    const uint32_t bits = m_log_size[t];
    return (pc ^ (pc >> (bits - uint32_t(t) % bits)) ^ m_fold_index[t].value ^
            (uint32_t(t) * 0x9e37u)) &
           ((1u << bits) - 1);
}

uint16_t TagePredictor::tag(int t, uint32_t pc) const {
    return uint16_t((pc ^ m_fold_tag0[t].value ^ (m_fold_tag1[t].value << 1)) &
                    ((1u << m_tag_bits[t]) - 1));
}

void TagePredictor::push_history(bool taken) {
    m_head = (m_head + k_history_slots - 1) % k_history_slots;
    m_history[m_head] = taken;
    for (int t = 0; t < k_tables; ++t) {
        const uint8_t oldest = m_history[(m_head + m_history_length[t]) % k_history_slots];
        m_fold_index[t].update(taken, oldest);
        m_fold_tag0[t].update(taken, oldest);
        m_fold_tag1[t].update(taken, oldest);
    }
}

bool TagePredictor::predict_and_update(uint32_t pc, bool taken) {
    std::array<uint32_t, k_tables> idx;
    std::array<uint16_t, k_tables> tags;
    int provider = -1, alt = -1;
    for (int t = k_tables - 1; t >= 0; --t) {
        idx[t] = index(t, pc);
        tags[t] = tag(t, pc);
        if (m_table[t][idx[t]].tag != tags[t]) continue;
        if (provider < 0)
            provider = t;
        else if (alt < 0)
            alt = t;
    }
    int8_t& base = m_base[pc & ((1u << k_log_base) - 1)];
    const bool base_pred = base >= 0;
    const bool alt_pred = alt >= 0 ? m_table[alt][idx[alt]].ctr >= 0 : base_pred;
    bool provider_pred = base_pred, prediction = base_pred, fresh = false;
    if (provider >= 0) {
        const Entry& e = m_table[provider][idx[provider]];
        provider_pred = e.ctr >= 0;
        fresh = (e.ctr == 0 || e.ctr == -1) && e.u == 0;
        prediction = fresh && m_use_alt_on_new >= 0 ? alt_pred : provider_pred;
    }
    const bool mispredicted = prediction != taken;
    ++m_branches;
    m_mispredictions += mispredicted;

    if (fresh && provider_pred != alt_pred)
        m_use_alt_on_new = std::clamp(m_use_alt_on_new + (alt_pred == taken ? 1 : -1), -8, 7);
    // A wrong provider allocates an entry in one longer table whose entry is not useful (the
    // first such, or the second with probability 1/2), else ages the longer ones.
    if (provider_pred != taken && provider < k_tables - 1) {
        int chosen = -1;
        for (int t = provider + 1; t < k_tables; ++t) {
            if (m_table[t][idx[t]].u != 0) continue;
            if (chosen < 0) {
                chosen = t;
                m_seed = m_seed * 1103515245u + 12345u;
                if ((m_seed >> 16) & 1) continue;
                break;
            }
            chosen = t;
            break;
        }
        if (chosen >= 0)
            m_table[chosen][idx[chosen]] = Entry{int8_t(taken ? 0 : -1), tags[chosen], 0};
        else
            for (int t = provider + 1; t < k_tables; ++t)
                if (m_table[t][idx[t]].u > 0) --m_table[t][idx[t]].u;
    }
    if (provider >= 0) {
        Entry& e = m_table[provider][idx[provider]];
        e.ctr = int8_t(std::clamp(e.ctr + (taken ? 1 : -1), -4, 3));
        if (provider_pred != alt_pred)
            e.u = uint8_t(std::clamp(int(e.u) + (provider_pred == taken ? 1 : -1), 0, 3));
        if (e.u == 0 && alt < 0) base = int8_t(std::clamp(base + (taken ? 1 : -1), -2, 1));
    } else {
        base = int8_t(std::clamp(base + (taken ? 1 : -1), -2, 1));
    }
    if (m_branches % k_useful_reset_period == 0)
        for (auto& table : m_table)
            for (Entry& e : table) e.u >>= 1;
    push_history(taken);
    return mispredicted;
}

uint32_t TagePredictor::run_counted_loop(uint32_t pc, uint32_t trips) {
    if (trips < 2) return 0;
    if (!m_counted_loops) m_counted_loops = std::make_unique<TagePredictor>();
    uint32_t missed = 0;
    for (uint32_t t = 2; t <= trips; ++t)
        missed += m_counted_loops->predict_and_update(pc, t < trips);
    m_branches += trips - 1;
    m_counted_loop_branches += trips - 1;
    m_mispredictions += missed;
    return missed;
}

std::vector<TraversalLoop> traversal_loops(const PassBuffer& pass, uint32_t width) {
    std::vector<TraversalLoop> loop(pass.size(), TraversalLoop::stream);
    for (uint32_t i = 0; i < pass.size(); ++i) {
        const StreamOp op = pass.at(i);
        const int32_t producer = pass.producer(i);
        const TraversalLoop from = producer < 0 ? TraversalLoop::stream : loop[size_t(producer)];
        if (op.kind == OpKind::box_test)
            loop[i] = traversal_loop(op.length, width, from);
        else if (op.stage == OpStage::intersection)
            loop[i] = from;  // its leaf's box test's: the tracer runs the leaf in that loop
    }
    return loop;
}

namespace {

// The static branches of the traversal (kernels/stream/stream_kernels_impl.h), one address each.
enum class Branch : uint32_t {
    stream_one_ray,     // traverse: len == 1
    stream_few_ray,     // traverse: len <= k_few_ray_lanes (wide back ends)
    stream_group,       // box_filter's group loop: a second group
    stream_group_loop,  // the same loop's further tests (run_counted_loop's own history)
    stream_copy_loop,   // copy_ids's loop over the failing ids, 8 a trip (the same history)
    stream_none,        // traverse: k == 0
    stream_leaf,        // traverse: node.is_leaf()
    few_one_ray,        // traverse_few: n == 1
    few_none,           // traverse_few: k == 0
    few_leaf,           // traverse_few: node.is_leaf()
    stream_prefetch,    // prefetch_below in the stream loop: node.is_leaf()
    few_prefetch,       // the same in traverse_few
    one_prefetch,       // the same in traverse_one
    one_stack,          // traverse_one: another node on its stack
    one_pass,           // traverse_one: the ray passes
    one_leaf,           // traverse_one: node.is_leaf()
    leaf_took_wide,     // traverse_leaf: a lane took the hit
    leaf_took_one,      // the same, one lane
    leaf_more_wide,     // traverse_leaf: another primitive
    leaf_more_one,
};
uint32_t address(Branch b) {
    return 0x401000u + 0x40u * uint32_t(b);
}

}  // namespace

void replay_traversal_branches(const PassBuffer& pass, const std::vector<TraversalLoop>& loops,
                               uint32_t width, const std::vector<uint8_t>& node_leaf,
                               TagePredictor& predictor, std::vector<uint32_t>& mispredicted) {
    const size_t n = pass.size();
    mispredicted.assign(n, 0);
    const bool few_loop = width >= k_few_ray_min_width;
    for (size_t i = 0; i < n; ++i) {
        const StreamOp op = pass.at(i);
        const bool next_is_leaf_test = i + 1 < n && (pass.at(i + 1).kind == OpKind::triangle_test ||
                                                     pass.at(i + 1).kind == OpKind::sphere_test);
        uint32_t& missed = mispredicted[i];
        auto branch = [&](Branch b, bool taken) {
            missed += predictor.predict_and_update(address(b), taken);
        };
        if (op.kind == OpKind::triangle_test || op.kind == OpKind::sphere_test) {
            const bool one = op.length == 1;
            branch(one ? Branch::leaf_took_one : Branch::leaf_took_wide, op.pass_count > 0);
            branch(one ? Branch::leaf_more_one : Branch::leaf_more_wide, next_is_leaf_test);
            continue;
        }
        if (op.kind != OpKind::box_test) continue;
        const uint32_t len = op.length, k = op.pass_count;
        const int32_t producer = pass.producer(i);
        const TraversalLoop from = producer < 0 ? TraversalLoop::stream : loops[size_t(producer)];
        const bool node_is_leaf =
            op.object < node_leaf.size() ? node_leaf[op.object] != 0 : next_is_leaf_test;
        const bool leaf = k > 0 && node_is_leaf;
        // The stream loop pops every stream it or its root made, and sends short ones on.
        if (loops[i] == TraversalLoop::stream || from == TraversalLoop::stream) {
            branch(Branch::stream_one_ray, len == 1);
            if (len > 1 && few_loop) branch(Branch::stream_few_ray, len <= k_few_ray_lanes);
        } else if (loops[i] == TraversalLoop::few_ray) {
            branch(Branch::few_one_ray, len == 1);
        }
        if (len == 1) {
            // A one-ray traversal starts where its stream came from a longer one.
            const bool starts = producer < 0 || pass.at(size_t(producer)).length > 1;
            branch(Branch::one_stack, !starts);
            branch(Branch::one_prefetch, node_is_leaf);
            branch(Branch::one_pass, k > 0);
            if (k > 0) branch(Branch::one_leaf, leaf);
        } else if (loops[i] == TraversalLoop::few_ray) {
            branch(Branch::few_prefetch, node_is_leaf);
            branch(Branch::few_none, k == 0);
            if (k > 0) branch(Branch::few_leaf, leaf);
        } else {
            branch(Branch::stream_prefetch, node_is_leaf);
            // The group loop as one branch an op, whether it runs a second group: its branch a
            // group put one entry in the global history per group, as many as a stream's lanes
            // over the width (a 500-lane op: 63 at 8 lanes, 32 at 16, 500 at 1), and the model's
            // mispredictions in the short loops, the same code on every wide back end, then
            // followed the width where the core's cost did not (the branch microbenchmark's
            // few-ray loop on the AMD Zen 4 VM, 2026-12-04: 7093 mispredictions added at 8
            // lanes, 6232 at 16, the core's 621 and 611 thousand cycles; one an op: 5754, 5780).
            branch(Branch::stream_group, len > width);
            // The loop's further tests and the copy of the failing ids: their exits follow
            // the op's length, which a frame never repeats (run_counted_loop). Without them
            // (AMD Zen 5 VM, 2026-12-05, cornell 64 x 64 at tiles 8 / 16 / 32 / 64: 3590 / 904
            // / 228 / 60 stream-loop box tests) the core's traversal grew 72-142 cycles a box
            // test more than the model's from each tile to the next smaller one at AVX2 and
            // AVX-512, and tile 16's traversal was priced 100 / 86 K cycles under the measured
            // where tile 32's was 51 / 14 K under (AVX2 / AVX-512); with them, on the same host
            // files, 14 / 25 K and 16 / -12 K.
            missed += predictor.run_counted_loop(address(Branch::stream_group_loop),
                                                 lane_groups(len, width));
            if (len - k >= 8)
                missed += predictor.run_counted_loop(address(Branch::stream_copy_loop),
                                                     (len - k) / 8 + 1);
            branch(Branch::stream_none, k == 0);
            if (k > 0) branch(Branch::stream_leaf, leaf);
        }
    }
}

namespace {

// Of the mispredictions op by op in `scratch` (mispredictions_replaying's), the box tests' by
// the loop that runs them.
std::array<uint64_t, 3> box_mispredictions_by_loop(const PassBuffer& pass,
                                                   const std::vector<TraversalLoop>& loops,
                                                   const std::vector<uint32_t>& scratch) {
    std::array<uint64_t, 3> by_loop{};
    for (size_t i = 0; i < scratch.size(); ++i)
        if (pass.at(i).kind == OpKind::box_test) by_loop[size_t(loops[i])] += scratch[i];
    return by_loop;
}

// `pass`'s traversal branches through `predictor`: the mispredictions they add.
uint64_t mispredictions_replaying(const PassBuffer& pass, const std::vector<TraversalLoop>& loops,
                                  uint32_t width, const std::vector<uint8_t>& node_leaf,
                                  TagePredictor& predictor, std::vector<uint32_t>& scratch) {
    const uint64_t before = predictor.mispredictions();
    replay_traversal_branches(pass, loops, width, node_leaf, predictor, scratch);
    return predictor.mispredictions() - before;
}

}  // namespace

PredictorStates simulate_predictor_states(const std::vector<const PassBuffer*>& batches,
                                          uint32_t width, const std::vector<uint8_t>& node_leaf,
                                          uint32_t repetitions) {
    std::vector<std::vector<TraversalLoop>> loops;
    for (const PassBuffer* b : batches) loops.push_back(traversal_loops(*b, width));
    TagePredictor predictor;
    std::vector<uint32_t> scratch;
    auto run = [&](size_t b) {
        return mispredictions_replaying(*batches[b], loops[b], width, node_leaf, predictor,
                                        scratch);
    };
    // Keeps batch b's run just made (`m` mispredictions, op by op in `scratch`) if it is the
    // fewest yet, with its box tests' by their loop.
    auto keep_fewest = [&](size_t b, uint64_t m, uint64_t& fewest,
                           std::array<uint64_t, 3>& fewest_by_loop) {
        if (m >= fewest) return;
        fewest = m;
        fewest_by_loop = box_mispredictions_by_loop(*batches[b], loops[b], scratch);
    };
    PredictorStates states;
    const uint64_t start = predictor.branches();
    for (size_t b = 0; b < batches.size(); ++b) run(b);
    states.branches = predictor.branches() - start;
    // Primed: as the microbenchmark's samples, each an untimed run of the batch and a timed
    // one, until the fewest mispredictions stopped falling for two samples (the predictor has
    // learned what it will; the microbenchmark keeps its fastest sample), at most 16.
    for (size_t b = 0; b < batches.size(); ++b) {
        uint64_t fewest = ~uint64_t(0);
        std::array<uint64_t, 3> fewest_by_loop{};
        for (uint32_t r = 0, steady = 0; r < 16 && (r < repetitions || steady < 2); ++r) {
            run(b);
            const uint64_t m = run(b);
            steady = m < fewest ? 0 : steady + 1;
            keep_fewest(b, m, fewest, fewest_by_loop);
        }
        states.primed += fewest;
        for (size_t l = 0; l < 3; ++l) states.primed_by_loop[l] += fewest_by_loop[l];
    }
    for (size_t b = 0; b < batches.size(); ++b) {
        uint64_t fewest = ~uint64_t(0);
        std::array<uint64_t, 3> fewest_by_loop{};
        for (uint32_t r = 0; r < repetitions; ++r) {
            for (size_t o = 0; o < batches.size(); ++o)
                if (o != b) run(o);
            keep_fewest(b, run(b), fewest, fewest_by_loop);
        }
        states.displaced += fewest;
        for (size_t l = 0; l < 3; ++l) states.displaced_by_loop[l] += fewest_by_loop[l];
    }
    return states;
}

bool is_traversal_op(OpKind kind) {
    return kind == OpKind::box_test || stage_of(kind) == OpStage::intersection;
}

PredictorStates unseen_ops_states(const std::vector<const PassBuffer*>& batches, uint32_t width) {
    PredictorStates states;
    for (const PassBuffer* b : batches) {
        const std::vector<TraversalLoop> loops = traversal_loops(*b, width);
        for (uint32_t i = 0; i < b->size(); ++i) {
            const OpKind kind = b->at(i).kind;
            states.displaced += is_traversal_op(kind);
            if (kind == OpKind::box_test) ++states.displaced_by_loop[size_t(loops[i])];
        }
    }
    states.branches = states.displaced;
    return states;
}

uint64_t simulate_displaced_batch(const PassBuffer& others, const PassBuffer& batch, uint32_t width,
                                  const std::vector<uint8_t>& node_leaf,
                                  std::array<uint64_t, 3>* box_by_loop) {
    TagePredictor predictor;
    std::vector<uint32_t> scratch;
    const std::vector<TraversalLoop> others_loops = traversal_loops(others, width);
    // The others twice: the first run warms the fresh predictor, as a core's is warm by the
    // time a batch is timed; the second is the run before the timed one.
    for (int run = 0; run < 2; ++run)
        mispredictions_replaying(others, others_loops, width, node_leaf, predictor, scratch);
    const std::vector<TraversalLoop> loops = traversal_loops(batch, width);
    const uint64_t missed =
        mispredictions_replaying(batch, loops, width, node_leaf, predictor, scratch);
    if (box_by_loop) *box_by_loop = box_mispredictions_by_loop(batch, loops, scratch);
    return missed;
}

double fit_mispredict_cycles(const std::vector<double>& extra_cycles,
                             const std::vector<double>& extra_mispredictions) {
    double cycles = 0.0, mispredictions = 0.0;
    for (size_t i = 0; i < extra_cycles.size() && i < extra_mispredictions.size(); ++i) {
        cycles += extra_cycles[i];
        mispredictions += extra_mispredictions[i];
    }
    return mispredictions > 0 ? std::max(0.0, cycles / mispredictions) : 0.0;
}

}  // namespace sfx
