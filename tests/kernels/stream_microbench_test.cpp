// The stage clock and the microbenchmarks of the native filters: the flow on tiny inputs (no
// timing is asserted beyond "it counted something").

#include "kernels/stream/stream_microbench.h"

#include <algorithm>
#include <catch2/catch.hpp>
#include <cmath>
#include <cstring>
#include <map>
#include <set>

#include "kernels/bvh.h"
#include "kernels/stream/stream_tracer.h"
#include "workloads/scene_loader.h"

using namespace sfx;

TEST_CASE("The stage clock never changes a bit and counts every stage", "[stream][host]") {
    const Scene scene = load_scene("cornell");
    const Bvh bvh(scene);
    RenderSettings s;
    s.width = s.height = 24;
    s.spp = 1;
    s.tile = 8;
    s.threads = 2;
    const RenderResult plain = render_stream(scene, bvh, s);
    s.stage_clock = true;
    const RenderResult clocked = render_stream(scene, bvh, s);
    REQUIRE(plain.image.pixels.size() == clocked.image.pixels.size());
    CHECK(std::memcmp(plain.image.pixels.data(), clocked.image.pixels.data(),
                      plain.image.pixels.size() * sizeof(Vec3)) == 0);
    for (int i = 0; i < 3; ++i) {
        CHECK(plain.stats.stage_tsc[i] == 0);
        CHECK(clocked.stats.stage_tsc[i] > 0);
    }
    // The shading stage is laps of one clock: its op kinds, the ray set-up and its rest make it
    // to the tick (two reads a part, a start and an end, left the ticks between parts in none).
    uint64_t laps = clocked.stats.ray_setup_tsc + clocked.stats.shading_rest_tsc;
    for (uint64_t ticks : clocked.stats.shading_op_tsc) laps += ticks;
    CHECK(laps == clocked.stats.stage_tsc[2]);
    CHECK(clocked.stats.shading_rest_tsc > 0);  // the sums into the image
    CHECK(plain.stats.shading_rest_tsc == 0);
}

TEST_CASE("The part clock never changes a bit and times each generation of each pass in order",
          "[stream][host]") {
    const Scene scene = load_scene("cornell");
    const Bvh bvh(scene);
    RenderSettings s;
    s.width = s.height = 24;
    s.spp = 2;
    s.tile = 8;
    s.threads = 1;
    s.max_depth = 3;
    const RenderResult plain = render_stream(scene, bvh, s);
    CHECK(plain.stats.part_tsc.empty());
    s.part_clock = true;
    const RenderResult timed = render_stream(scene, bvh, s);
    REQUIRE(plain.image.pixels.size() == timed.image.pixels.size());
    CHECK(std::memcmp(plain.image.pixels.data(), timed.image.pixels.data(),
                      plain.image.pixels.size() * sizeof(Vec3)) == 0);
    // 9 tiles x 2 passes, each of at most max_depth + 1 generations and its end; every render
    // of the frame has the same parts.
    CHECK(timed.stats.part_tsc.size() > 9 * 2 * 2);
    CHECK(timed.stats.part_tsc.size() <= 9 * 2 * (3 + 2));
    for (uint64_t ticks : timed.stats.part_tsc) CHECK(ticks > 0);
    // Each part's start, in order, none before the last one's end.
    REQUIRE(timed.stats.part_start_tsc.size() == timed.stats.part_tsc.size());
    for (size_t p = 1; p < timed.stats.part_tsc.size(); ++p)
        CHECK(timed.stats.part_start_tsc[p] >=
              timed.stats.part_start_tsc[p - 1] + timed.stats.part_tsc[p - 1]);
    CHECK(render_stream(scene, bvh, s).stats.part_tsc.size() == timed.stats.part_tsc.size());
}

TEST_CASE(
    "The stage clock splits the traversal and its leaves by the loop that runs its short streams",
    "[stream][host]") {
    // Atrium's 64-ray streams narrow to one ray (the one-ray loop) on every back end, and to
    // two to four (the few-ray loop) where the back end has k_few_ray_min_width lanes or more.
    const Scene scene = load_scene("atrium");
    const Bvh bvh(scene);
    RenderSettings s;
    s.width = s.height = 24;
    s.spp = 1;
    s.tile = 8;
    s.threads = 1;
    s.max_depth = scene.max_depth;
    for (const Isa isa : supported_isas()) {
        INFO(isa_name(isa));
        s.isa = isa;
        s.stage_clock = false;
        const RenderResult plain = render_stream(scene, bvh, s);
        s.stage_clock = true;
        const RenderResult clocked = render_stream(scene, bvh, s);
        CHECK(plain.stats.short_loop_tsc[0] + plain.stats.short_loop_tsc[1] == 0);
        CHECK(clocked.stats.short_loop_tsc[0] > 0);
        CHECK((clocked.stats.short_loop_tsc[1] > 0) == (isa_width(isa) >= k_few_ray_min_width));
        CHECK(clocked.stats.short_loop_tsc[0] + clocked.stats.short_loop_tsc[1] <
              clocked.stats.stage_tsc[0]);
        // The leaves the short loops reach: in the intersection stage, the stream loop's the rest.
        CHECK(plain.stats.short_loop_leaf_tsc[0] + plain.stats.short_loop_leaf_tsc[1] == 0);
        CHECK(clocked.stats.short_loop_leaf_tsc[0] > 0);
        CHECK((clocked.stats.short_loop_leaf_tsc[1] > 0) ==
              (isa_width(isa) >= k_few_ray_min_width));
        CHECK(clocked.stats.short_loop_leaf_tsc[0] + clocked.stats.short_loop_leaf_tsc[1] <
              clocked.stats.stage_tsc[1]);
    }
}

TEST_CASE("A microbenchmark point's repetitions come from every visit of the sweep",
          "[stream][host]") {
    MicrobenchOptions o;
    o.buffer_slots = {64, 256};
    o.lengths = {8, 16};
    o.kinds = {OpKind::box_test, OpKind::miss_filter};
    o.convergence = microbench_rule(4);  // 4 to 4 repetitions a visit
    for (const uint32_t visits : {1u, 3u}) {
        o.visits = visits;
        const std::vector<MicrobenchSample> samples = run_stream_microbenchmarks(o);
        // The same points whatever the visits: box tests 2 x 2, the miss filter's also on
        // streams that all pass and that none pass.
        REQUIRE(samples.size() == 4 + 12);
        for (const MicrobenchSample& m : samples) {
            CHECK(m.repetitions == 4 * visits);
            CHECK(m.cycles > 0.0);
        }
    }
}

TEST_CASE("Microbenchmarks time every op kind of the native tracer", "[stream][host]") {
    MicrobenchOptions o;
    o.buffer_slots = {256};
    o.lengths = {1, 16, 64, 512};  // 512 > 256 slots: skipped
    o.convergence = microbench_rule(1);
    const std::vector<MicrobenchSample> samples = run_stream_microbenchmarks(o);
    std::set<OpKind> kinds;
    for (const MicrobenchSample& m : samples) {
        kinds.insert(m.kind);
        CHECK(m.slots == 256);
        CHECK(m.lanes <= 256);
        CHECK(m.passed <= m.lanes);
        CHECK(m.cycles >= 0.0);
    }
    // Every kind of the plain tracer; a workload option's own kinds (entry-point search,
    // reordering) are not benchmarked, so a host file has no cost for them.
    uint32_t plain_kinds = 0;
    for (uint32_t k = 0; k < k_op_kind_count; ++k) plain_kinds += !is_option_kind(OpKind(k));
    CHECK(kinds.size() == plain_kinds);
    // Three lengths each; a shading op or a leaf test whose buffer has rays it passes and rays
    // it fails also on streams that all pass and streams that none pass, after its mixed ones
    // (a leaf test's one-lane stream only all passing and none passing: 2 + 3 + 3).
    // The camera's also on a thin lens, apart (thin_lens_per_lane_cycles), the direct-light
    // filter's on a sphere light (sphere_light_per_pass_cycles), and the triangle test's on
    // candidates that fail (per_failed_candidate_cycles), and the emission filter's on sphere
    // hits (sphere_hit_per_lane_cycles; its plain ones on triangle hits); no other kind's.
    std::map<OpKind, std::vector<const MicrobenchSample*>> by_kind;
    std::vector<const MicrobenchSample*> lens, sphere_light, failing, sphere_hits;
    for (const MicrobenchSample& m : samples)
        (m.thin_lens            ? lens
         : m.sphere_light       ? sphere_light
         : m.failing_candidates ? failing
         : m.sphere_hits        ? sphere_hits
                                : by_kind[m.kind])
            .push_back(&m);
    // The synthetic scene's sphere is glass and its buffers' rays hit the light from above
    // (no lane passes the emission filter), so both kinds' streams are mixed ones only.
    REQUIRE(sphere_hits.size() == 3);
    for (const MicrobenchSample* m : sphere_hits) {
        CHECK(m->kind == OpKind::emission_filter);
        CHECK(m->passed == 0);
        CHECK(m->variant());
    }
    CHECK(by_kind[OpKind::emission_filter].size() == 3);
    // Streams of every lane failing, one lane long too (one_lane_failed_candidate_cycles): each
    // lane's ray turned round or given a closer hit still crosses the triangle (the tracer's
    // float stage counts it a candidate).
    REQUIRE(failing.size() == 3);
    CHECK(failing[0]->lanes == 1);
    for (const MicrobenchSample* m : failing) {
        CHECK(m->kind == OpKind::triangle_test);
        CHECK(m->passed == 0);
        CHECK(m->failed_candidates == m->lanes);
    }
    REQUIRE(lens.size() == 3);
    for (const MicrobenchSample* m : lens) CHECK(m->kind == OpKind::camera);
    CHECK(by_kind[OpKind::camera].size() == 3);
    // Mixed streams, and all-passing and none-passing ones where the sphere light's samples
    // both pass and fail.
    CHECK((sphere_light.size() == 3 || sphere_light.size() == 9));
    for (const MicrobenchSample* m : sphere_light) CHECK(m->kind == OpKind::lambertian_direct);
    for (const auto& [kind, of_kind] : by_kind) {
        INFO(to_string(kind));
        if (of_kind.size() == 3) continue;
        if (stage_of(kind) == OpStage::intersection) {
            REQUIRE(of_kind.size() == 8);
            for (int i = 0; i < 2; ++i) CHECK(of_kind[i]->lanes > 1);
            CHECK(of_kind[2]->lanes == 1);
            CHECK(of_kind[5]->lanes == 1);
            for (int i = 0; i < 3; ++i) {
                CHECK(of_kind[2 + i]->passed == of_kind[2 + i]->lanes);
                CHECK(of_kind[5 + i]->passed == 0);
                // From no hit, a ray whose line crosses the triangle hits it; a ray the
                // triangle fails is not a candidate.
                CHECK(of_kind[2 + i]->failed_candidates == 0);
                CHECK(of_kind[5 + i]->failed_candidates == 0);
            }
            continue;
        }
        REQUIRE(of_kind.size() == 9);
        CHECK(stage_of(kind) == OpStage::shading);
        for (int i = 0; i < 3; ++i) {
            CHECK(of_kind[3 + i]->passed == of_kind[3 + i]->lanes);
            CHECK(of_kind[6 + i]->passed == 0);
        }
    }
    // Both leaf tests are classified (the floor triangle and the sphere each hit by some of
    // the buffer's rays and missed by others).
    CHECK(by_kind[OpKind::triangle_test].size() == 8);
    CHECK(by_kind[OpKind::sphere_test].size() == 8);
    REQUIRE(by_kind[OpKind::lambertian_direct].size() == 9);
    const MicrobenchSample& mixed = *by_kind[OpKind::lambertian_direct][2];
    CHECK(mixed.passed > 0);
    CHECK(mixed.passed < mixed.lanes);
    // The kinds a frame gives only hits are dealt only hits: a bounce is made from every hit,
    // so the lambertian bounce has no failing lanes (the buffer's misses failed it before).
    CHECK(frame_streams_hold_hits_only(OpKind::lambertian_indirect));
    CHECK_FALSE(frame_streams_hold_hits_only(OpKind::miss_filter));
    CHECK(by_kind[OpKind::lambertian_indirect].size() == 3);
    for (const MicrobenchSample* m : by_kind[OpKind::lambertian_indirect])
        CHECK(m->passed == m->lanes);
    for (OpKind k : kinds) CHECK_FALSE(is_option_kind(k));
    // Some pass and some fail: the synthetic streams exercise both sides of the filters.
    uint64_t lanes = 0, passed = 0;
    for (const MicrobenchSample& m : samples)
        if (m.kind == OpKind::miss_filter || m.kind == OpKind::box_test) {
            lanes += m.lanes;
            passed += m.passed;
        }
    CHECK(passed > 0);
    CHECK(passed < lanes);
    CHECK(stream_slot_bytes() > 64);
}

TEST_CASE("A microbenchmark repetition asks the caches to hold the tracer's arrays of a pass",
          "[stream][host]") {
    // The fit prices a point's lanes beyond the L1D and the L2 by stream_slot_bytes: the arrays
    // the touch before the timed calls reads (Buffers::for_each_slot_element) and the id lists
    // must be those. (Arrays of the microbenchmark's own, a made ray's set-up apart from the
    // pass's, +43 %, put its largest buffer beyond an L2 that holds a tile's rays.)
    for (const uint32_t slots : {64u, 4096u})
        CHECK(microbench_timed_slot_bytes(slots) ==
              Approx(double(stream_slot_bytes())).epsilon(0.05));
}

TEST_CASE("The surface reads beyond the caches are timed on the tracer's own loop",
          "[stream][host]") {
    // compute_surfaces (the tracer's loop, with its prefetches) gives every id surface_at's
    // surface, bit for bit.
    const Scene scene = load_scene("cornell");
    const Bvh bvh(scene);
    std::vector<Ray> rays;
    std::vector<Hit> hits;
    std::vector<uint32_t> ids;
    for (uint32_t i = 0; i < 64; ++i) {
        Ray r;
        r.org = scene.camera.eye;
        const Vec3 ahead = normalize(scene.camera.look_at - scene.camera.eye);
        r.dir = normalize(ahead + Vec3(float(i % 8) - 3.5f, float(i / 8) - 3.5f, 0.f) * 0.05f);
        rays.push_back(r);
        hits.push_back(bvh.intersect(r));
        if (hits.back().valid() && i % 3 != 1) ids.push_back(i);  // a sparse stream of hits
    }
    REQUIRE(ids.size() > 20);
    std::vector<SurfaceHit> surf(64);
    compute_surfaces(scene, rays.data(), hits.data(), ids.data(), uint32_t(ids.size()),
                     surf.data());
    for (uint32_t id : ids) {
        const SurfaceHit s = surface_at(scene, rays[id], hits[id]);
        CHECK(std::memcmp(&s.position, &surf[id].position, sizeof(Vec3)) == 0);
        CHECK(std::memcmp(&s.normal, &surf[id].normal, sizeof(Vec3)) == 0);
        CHECK(s.material == surf[id].material);
    }

    const std::vector<SurfaceReadSample> samples =
        run_surface_read_microbenchmarks(Isa::automatic, microbench_rule(1));
    REQUIRE(samples.size() == 3);
    for (const SurfaceReadSample& s : samples) {
        CHECK(s.lanes == 4096);
        CHECK(s.cycles > 0.0);
        CHECK(s.resident_cycles > 0.0);
        CHECK(s.repetitions == 1);
        // The draw replays: the same hits for the same repetition, others for the next, all
        // inside the mesh.
        const std::vector<uint32_t> a = surface_read_hits(s, 0);
        CHECK(a == surface_read_hits(s, 0));
        CHECK(a != surface_read_hits(s, 1));
        CHECK(*std::max_element(a.begin(), a.end()) < s.triangles);
    }
    CHECK(samples[0].triangles == 1u << 13);
    CHECK(samples[2].triangles == 1u << 20);
}

TEST_CASE("The branch predictor's part is timed on a scene's tile batches in three states",
          "[stream][host]") {
    const Scene scene = load_scene("cornell");
    const Bvh bvh(scene);
    for (const std::vector<PredictorSample>& samples :
         {run_predictor_microbenchmarks(scene, bvh, Isa::automatic, microbench_rule(1)),
          run_predictor_microbenchmarks(Isa::automatic, microbench_rule(1))}) {
        REQUIRE(samples.size() == 2);
        CHECK_FALSE(samples[0].bounce);
        CHECK(samples[1].bounce);
        for (const PredictorSample& s : samples) {
            CHECK(s.batches == 16);           // the 16 x 16 tiles of a 64 x 64 frame
            CHECK(s.box_tests >= s.batches);  // every batch tests the root at least
            CHECK(s.lines >= s.batches);
            CHECK(s.primed.cycles > 0.0);
            CHECK(s.cached.cycles > 0.0);
            CHECK(s.displaced.cycles > 0.0);
            CHECK(s.converged_batches == s.batches);  // the fastest 1 of 1 agrees with itself
            // Each state split by loop, box tests and leaves apart: together its cycles (the
            // stream loop's box tests are the rest; each part a median of clocked repetitions,
            // so the sum is near it).
            for (const BatchStateCycles* state : {&s.primed, &s.cached, &s.displaced}) {
                const std::array<double, 3>&loops = state->loops, &leaves = state->leaves;
                const double in_loops = loops[0] + loops[1] + loops[2];
                const double in_leaves = leaves[0] + leaves[1] + leaves[2];
                CHECK(in_loops > 0.0);
                CHECK(in_leaves > 0.0);  // every batch reaches leaves of cornell's triangles
                CHECK(in_loops + in_leaves <= 1.2 * state->cycles);
                CHECK(in_loops + in_leaves >= 0.8 * state->cycles);
                for (const double c :
                     {loops[0], loops[1], loops[2], leaves[0], leaves[1], leaves[2]})
                    CHECK(c >= 0.0);
                // The few-ray loop and its leaves run only on a back end that has it.
                if (isa_width(resolve_isa(Isa::automatic)) < k_few_ray_min_width) {
                    CHECK(loops[1] == 0.0);
                    CHECK(leaves[1] == 0.0);
                }
            }
        }
    }
    // The evicted state, and each batch's trace to the caller's sink: 16 camera batches, then
    // 16 of bounces, each one pass of both kinds' slots.
    struct Passes : TraceSink {
        std::vector<TilePass> begun;
        uint64_t ops = 0;
        void begin_pass(const TilePass& p) override { begun.push_back(p); }
        void op(const StreamOp&) override { ++ops; }
    };
    Passes passes;
    std::vector<std::pair<bool, uint32_t>> asked;
    const std::vector<PredictorSample> traced = run_predictor_microbenchmarks(
        scene, bvh, Isa::automatic, microbench_rule(1), 3, [&](bool bounce, uint32_t batch) {
            asked.emplace_back(bounce, batch);
            return &passes;
        });
    REQUIRE(asked.size() == 32);
    CHECK(asked[15] == std::make_pair(false, 15u));
    CHECK(asked[16] == std::make_pair(true, 0u));
    CHECK(passes.begun.size() == 32);
    CHECK(passes.begun[0].slot_count == 2 * 64 * 64);
    CHECK(passes.ops >= traced[0].box_tests + traced[1].box_tests);
    CHECK(traced[0].evicted.cycles > 0.0);
    CHECK(run_predictor_microbenchmarks(scene, bvh, Isa::automatic, microbench_rule(1), 3, {},
                                        false)[0]
              .evicted.cycles == 0.0);
}

TEST_CASE("The shared-origin check is timed per lane over a tile's records", "[stream][host]") {
    // A few cycles a lane on any x86-64 core (3.2 on an AMD Zen 4 VM): a 12-byte compare of a
    // record's origin, one record (a cache line) a lane; a shared machine only adds time, so the
    // bound above is loose.
    const SharedOriginSample s = run_shared_origin_microbenchmark(Isa::automatic);
    CHECK(s.per_lane_cycles > 0.3);
    CHECK(s.per_lane_cycles < 60.0);
    CHECK(s.repetitions >= microbench_rule().min_samples);
}

TEST_CASE("A cold call's cost over a warm one resolves below the TSC's step", "[stream][host]") {
    // A TSC that steps by 36 ticks: calls of 100 and 150 ticks, starting anywhere in a step,
    // read as multiples of 36; over many pairs the mean difference is the true 50. One pair
    // interrupted (a cold call 40 times its median) is left out.
    std::vector<double> cold, warm;
    for (int i = 0; i < 360; ++i) {
        const double phase = double(i % 36);
        auto read = [&](double start, double length) {
            return std::floor((start + length) / 36.0) * 36.0 - std::floor(start / 36.0) * 36.0;
        };
        cold.push_back(read(phase, 150.0));
        warm.push_back(read(phase + 150.0, 100.0));
    }
    CHECK(cold_call_difference(cold, warm) == Approx(50.0).margin(1.0));
    cold[7] = 40 * 150.0;
    CHECK(cold_call_difference(cold, warm) == Approx(50.0).margin(1.0));
    CHECK(cold_call_difference({}, {}) == 0.0);
}

TEST_CASE("A shading op's mixed points of the cold lengths time its call cold and warm",
          "[stream][host]") {
    MicrobenchOptions o;
    o.buffer_slots = {64, 256};
    o.lengths = {8, 16, 24};
    o.cold_call_lengths = {8, 24};
    o.cold_call_pairs = 8;
    o.kinds = {OpKind::box_test, OpKind::miss_filter};
    o.convergence = microbench_rule(3);
    o.visits = 1;
    uint32_t timed = 0;
    for (const MicrobenchSample& m : run_stream_microbenchmarks(o)) {
        INFO(to_string(m.kind) << " " << m.slots << " slots, " << m.lanes << " lanes, " << m.passed
                               << " passed");
        // Only the miss filter's mixed points (passing some lanes and failing others) of the
        // buffer of 256 slots at 8 and 24 lanes; a traversal's start has its own.
        const bool mixed = m.passed > 0 && m.passed < m.lanes;
        const bool expected = m.kind == OpKind::miss_filter && m.slots == 256 && mixed &&
                              (m.lanes == 8 || m.lanes == 24);
        CHECK(m.cold_call_timed == expected);
        timed += m.cold_call_timed;
        if (!m.cold_call_timed) CHECK(m.cold_call_cycles == 0.0);
    }
    CHECK(timed == 2);
    // One value a length, of traversals from the root; a length two streams of which do not
    // fit the buffer is left out.
    const std::vector<double> traversal =
        run_cold_traversal_microbenchmarks(Isa::automatic, {16, 32, 512}, 4);
    CHECK(traversal.size() == 2);
    for (const double d : traversal) CHECK(std::isfinite(d));
}
