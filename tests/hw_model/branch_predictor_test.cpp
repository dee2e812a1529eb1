#include "hw_model/branch_predictor.h"

#include <catch2/catch.hpp>
#include <random>

using namespace sfx;

namespace {

// The share of `outcomes` (at the pcs given) the predictor mispredicts.
double mispredicted(TagePredictor& p, const std::vector<uint32_t>& pcs,
                    const std::vector<uint8_t>& outcomes) {
    const uint64_t before = p.mispredictions();
    for (size_t i = 0; i < outcomes.size(); ++i) p.predict_and_update(pcs[i], outcomes[i]);
    return double(p.mispredictions() - before) / double(outcomes.size());
}

// One op of a pass: a box test or a triangle test of `slots`, the first `passed` lanes passing.
void add_op(PassBuffer& pass, OpKind kind, uint32_t object, const std::vector<uint32_t>& slots,
            uint32_t passed) {
    std::vector<uint8_t> mask(slots.size(), 0);
    for (uint32_t i = 0; i < passed; ++i) mask[i] = 1;
    StreamOp op;
    op.kind = kind;
    op.stage = kind == OpKind::box_test ? OpStage::traversal : OpStage::intersection;
    op.object = object;
    op.length = uint32_t(slots.size());
    op.pass_count = passed;
    op.slots = slots.data();
    op.passed = mask.data();
    pass.op(op);
}

}  // namespace

TEST_CASE("The predictor learns a repeated sequence, never a random one", "[branch]") {
    std::mt19937 rng(1);
    std::vector<uint32_t> pcs(1000);
    std::vector<uint8_t> outcomes(1000);
    for (size_t i = 0; i < outcomes.size(); ++i) {
        outcomes[i] = rng() & 1;
        pcs[i] = 0x400000 + 64 * (rng() % 8);
    }
    TagePredictor p;
    const double first = mispredicted(p, pcs, outcomes);
    CHECK(first > 0.35);
    CHECK(first < 0.65);
    double later = 1.0;
    for (int rep = 0; rep < 6; ++rep) later = mispredicted(p, pcs, outcomes);
    CHECK(later < 0.05);
    // New random outcomes at the same branches: nothing to learn.
    for (uint8_t& o : outcomes) o = rng() & 1;
    CHECK(mispredicted(p, pcs, outcomes) > 0.35);
    // A loop of eight iterations: its exit is learned from the history.
    TagePredictor loop;
    std::vector<uint8_t> eights;
    for (int rep = 0; rep < 200; ++rep)
        for (int i = 0; i < 8; ++i) eights.push_back(i < 7);
    mispredicted(loop, std::vector<uint32_t>(eights.size(), 0x400040), eights);
    CHECK(mispredicted(loop, std::vector<uint32_t>(eights.size(), 0x400040), eights) < 0.01);
    CHECK(loop.branches() == 2 * eights.size());
}

TEST_CASE("A pass's traversal branches follow the tracer's loops", "[branch]") {
    // Width 8: a 16-lane box test on interior node 0, all passing; its child, leaf 1, which one
    // ray passes; that ray's triangle test, which it hits.
    const std::vector<uint32_t> sixteen = {0, 1, 2, 3, 4, 5, 6, 7, 8, 9, 10, 11, 12, 13, 14, 15};
    PassBuffer pass;
    TilePass tile;
    tile.slot_count = 16;
    pass.begin_pass(tile);
    add_op(pass, OpKind::box_test, 0, sixteen, 16);
    add_op(pass, OpKind::box_test, 1, sixteen, 1);
    add_op(pass, OpKind::triangle_test, 5, {0}, 1);
    pass.end_pass(tile);
    const std::vector<TraversalLoop> loops = traversal_loops(pass, 8);
    CHECK(loops[0] == TraversalLoop::stream);
    CHECK(loops[1] == TraversalLoop::stream);
    TagePredictor p;
    std::vector<uint32_t> missed;
    replay_traversal_branches(pass, loops, 8, {0, 1}, p, missed);
    // Each box test in the stream loop: one ray? few? leaf (prefetch)? a second group? none
    // passed? leaf? Six each in the global history. The triangle test: took the hit? another
    // primitive? Two. In the counted loops' own history: the group loop's test after the
    // second group of 16 lanes at 8, one an op; the copy of the second op's 15 failing ids,
    // one trip of 8 and its exit test.
    CHECK(p.branches() - p.counted_loop_branches() == 6 + 6 + 2);
    CHECK(p.counted_loop_branches() == 2 + 1);
    REQUIRE(missed.size() == 3);
    CHECK(missed[0] + missed[1] + missed[2] == p.mispredictions());
    // Without the tree's leaves a passing node is a leaf where leaf tests follow it.
    TagePredictor q;
    replay_traversal_branches(pass, loops, 8, {}, q, missed);
    CHECK(q.branches() == p.branches());
    // A narrow back end has no few-ray loop: no such test. The group loop is one branch an
    // op in the global history at any width (the short loops' predictions must not follow the
    // stream loop's width); its further tests, 3 an op of 4 groups, in its own, beside the
    // copy's, which runs 8 ids a trip at every width.
    TagePredictor r;
    replay_traversal_branches(pass, traversal_loops(pass, 4), 4, {0, 1}, r, missed);
    CHECK(r.branches() - r.counted_loop_branches() == 2 * (6 - 1) + 2);
    CHECK(r.counted_loop_branches() == 2 * 3 + 1);
    TagePredictor wide;
    replay_traversal_branches(pass, traversal_loops(pass, 16), 16, {0, 1}, wide, missed);
    CHECK(wide.branches() - wide.counted_loop_branches() ==
          p.branches() - p.counted_loop_branches());
    CHECK(wide.counted_loop_branches() == 1);
}

TEST_CASE("A counted loop's exit is learned where its trip counts repeat, not where they vary",
          "[branch]") {
    // A frame's stream-loop ops have lengths that do not repeat: a counted loop's exit is
    // mispredicted about once an op. A batch timed right after itself repeats them: learned.
    std::mt19937 rng(3);
    std::uniform_int_distribution<uint32_t> groups(3, 40);
    std::vector<uint32_t> batch(24);
    for (uint32_t& g : batch) g = groups(rng);
    TagePredictor fresh;
    uint32_t missed = 0;
    for (int op = 0; op < 2000; ++op) missed += fresh.run_counted_loop(7, groups(rng));
    CHECK(double(missed) / 2000 > 0.8);
    TagePredictor primed;
    for (int run = 0; run < 20; ++run)
        for (const uint32_t g : batch) primed.run_counted_loop(7, g);
    uint32_t again = 0;
    for (const uint32_t g : batch) again += primed.run_counted_loop(7, g);
    CHECK(double(again) / double(batch.size()) < 0.2);
    // A stream of one group runs no further test.
    CHECK(primed.run_counted_loop(7, 1) == 0);
}

TEST_CASE("A batch mispredicts less after itself than after others", "[branch]") {
    // Batches of one-ray traversals with outcomes at random: each its own sequence, together
    // more than the predictor holds.
    std::mt19937 rng(2);
    std::vector<PassBuffer> batches(8);
    std::vector<uint8_t> leaves(64, 0);
    for (PassBuffer& b : batches) {
        TilePass tile;
        tile.slot_count = 1;
        b.begin_pass(tile);
        for (int i = 0; i < 2000; ++i) add_op(b, OpKind::box_test, rng() % 64, {0}, rng() & 1);
        b.end_pass(tile);
    }
    std::vector<const PassBuffer*> views;
    for (const PassBuffer& b : batches) views.push_back(&b);
    const PredictorStates s = simulate_predictor_states(views, 8, leaves);
    CHECK(s.branches > 8 * 2000);
    CHECK(s.primed < s.displaced);
    CHECK(s.primed < s.branches / 20);
    // Every op is a one-ray box test: the one-ray loop holds every misprediction.
    CHECK(s.primed_by_loop[size_t(TraversalLoop::one_ray)] == s.primed);
    CHECK(s.displaced_by_loop[size_t(TraversalLoop::one_ray)] == s.displaced);
    CHECK(s.displaced_by_loop[size_t(TraversalLoop::stream)] == 0);

    CHECK(fit_mispredict_cycles({100, 200}, {2, 2}) == Approx(75));
    CHECK(fit_mispredict_cycles({100}, {0}) == 0.0);
    CHECK(fit_mispredict_cycles({-100}, {2}) == 0.0);
}

TEST_CASE("The unseen-ops predictor mispredicts each traversal op of a batch not just run",
          "[branch]") {
    // One batch: three one-ray box tests, a stream's box test of 16 lanes, a triangle test and
    // a sphere test.
    PassBuffer batch;
    TilePass tile;
    tile.slot_count = 16;
    batch.begin_pass(tile);
    std::vector<uint32_t> stream(16);
    for (uint32_t i = 0; i < 16; ++i) stream[i] = i;
    add_op(batch, OpKind::box_test, 0, stream, 16);
    for (int i = 0; i < 3; ++i) add_op(batch, OpKind::box_test, 1 + i, {0}, 1);
    add_op(batch, OpKind::triangle_test, 7, {0}, 1);
    add_op(batch, OpKind::sphere_test, 8, {0}, 0);
    batch.end_pass(tile);
    const PredictorStates s = unseen_ops_states({&batch, &batch}, 8);
    CHECK(s.primed == 0);  // just run: nothing unseen
    CHECK(s.displaced == 2 * 6);
    CHECK(s.displaced_by_loop[size_t(TraversalLoop::stream)] == 2 * 1);
    CHECK(s.displaced_by_loop[size_t(TraversalLoop::one_ray)] == 2 * 3);
    CHECK(s.displaced_by_loop[size_t(TraversalLoop::few_ray)] == 0);
    CHECK(is_traversal_op(OpKind::box_test));
    CHECK(is_traversal_op(OpKind::triangle_test));
    CHECK(is_traversal_op(OpKind::sphere_test));
    CHECK_FALSE(is_traversal_op(OpKind::camera));
    CHECK_FALSE(is_traversal_op(OpKind::lambertian_direct));
}
