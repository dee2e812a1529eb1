// The host back end (kernels/simd/isa.h) never changes a byte: the workload trace (every op's
// kind, object, slots in order and pass flags) and the hit records are the same for every back
// end the machine has and the scalar one. (Images: stream_tracer_test.cpp, every back end.)

#include <catch2/catch.hpp>
#include <cstring>
#include <string>
#include <vector>

#include "kernels/bvh.h"
#include "kernels/camera.h"
#include "kernels/rng.h"
#include "kernels/stream/stream_tracer.h"
#include "tests/kernels/test_scenes.h"

using namespace sfx;

namespace {

// The whole trace as bytes: pass headers, then each op's fields, slots and pass flags.
struct OpLog : TraceSink {
    std::string bytes;
    uint64_t ops = 0;
    template <class T>
    void put(const T& v) {
        bytes.append(reinterpret_cast<const char*>(&v), sizeof v);
    }
    void begin_pass(const TilePass& p) override {
        put(p.tile);
        put(p.sample);
        put(p.slot_count);
    }
    void op(const StreamOp& o) override {
        ++ops;
        put(o.kind);
        put(o.stage);
        put(o.generation);
        put(o.object);
        put(o.length);
        put(o.pass_count);
        bytes.append(reinterpret_cast<const char*>(o.slots), o.length * sizeof(uint32_t));
        bytes.append(reinterpret_cast<const char*>(o.passed), o.length);
    }
    void end_pass(const TilePass& p) override { put(p.generations); }
};

std::string trace_of(const Scene& s, const Bvh& bvh, RenderSettings r, Isa isa, uint64_t* ops) {
    r.isa = isa;
    OpLog log;
    render_stream(s, bvh, r, &log);
    if (ops) *ops = log.ops;
    return log.bytes;
}

RenderSettings settings_for(const Scene& s, uint32_t tile, uint32_t threads) {
    RenderSettings r;
    r.width = 24;
    r.height = 20;
    r.spp = 2;
    r.tile = tile;
    r.threads = threads;
    r.max_depth = s.max_depth;
    return r;
}

}  // namespace

TEST_CASE("The workload trace is identical for every back end (ops, slots, masks)",
          "[stream][simd]") {
    for (const test::Variant v :
         {test::Variant::lights, test::Variant::ambient, test::Variant::emissive_sphere}) {
        const Scene s = test::box_scene(v);
        const Bvh bvh(s);
        for (uint32_t tile : {4u, 16u})
            for (uint32_t threads : {1u, 2u}) {
                const RenderSettings r = settings_for(s, tile, threads);
                uint64_t ops = 0;
                const std::string scalar = trace_of(s, bvh, r, Isa::scalar, &ops);
                CHECK(ops > 100);
                for (const Isa isa : supported_isas()) {
                    INFO("scene " << s.name << " tile " << tile << " threads " << threads
                                  << " back end " << isa_name(isa));
                    CHECK(trace_of(s, bvh, r, isa, nullptr) == scalar);
                }
            }
    }
}

TEST_CASE("The trace comparison can fail: another seed gives another trace", "[stream][simd]") {
    const Scene s = test::box_scene(test::Variant::lights);
    const Bvh bvh(s);
    RenderSettings r = settings_for(s, 8, 1);
    const std::string a = trace_of(s, bvh, r, best_isa(), nullptr);
    r.seed = 3;
    CHECK(trace_of(s, bvh, r, best_isa(), nullptr) != a);
}

TEST_CASE("stream_intersect gives the same hits and trace for every back end", "[stream][simd]") {
    const Scene s = test::box_scene(test::Variant::emissive_sphere);
    const Bvh bvh(s);
    std::vector<Ray> rays;
    const CameraFrame camera(s.camera, 61, 53);  // not a multiple of any width
    for (uint32_t i = 0; i < 61 * 53; ++i) {
        Ray r = camera.generate({0, i, 0});
        auto coordinate = [&](uint32_t dim) {
            return float(random_bits(1, i, 0, 0, dim) >> 8) / 16777216.f - 0.5f;
        };
        if (i % 5 == 0) r.dir = Vec3(coordinate(0), coordinate(1), coordinate(2));
        if (i % 7 == 0) r.dir.y = -0.f;
        rays.push_back(r);
    }
    std::vector<Hit> scalar_hits;
    OpLog scalar_log;
    stream_intersect(bvh, rays, scalar_hits, &scalar_log, Isa::scalar);
    for (const Isa isa : supported_isas()) {
        INFO("back end " << isa_name(isa));
        std::vector<Hit> hits;
        OpLog log;
        stream_intersect(bvh, rays, hits, &log, isa);
        REQUIRE(hits.size() == scalar_hits.size());
        CHECK(std::memcmp(hits.data(), scalar_hits.data(), hits.size() * sizeof(Hit)) == 0);
        CHECK(log.bytes == scalar_log.bytes);
        std::vector<Hit> untraced;
        stream_intersect(bvh, rays, untraced, nullptr, isa);
        CHECK(std::memcmp(untraced.data(), scalar_hits.data(), hits.size() * sizeof(Hit)) == 0);
    }
}

TEST_CASE("Back ends: auto picks the widest the CPU has, an unsupported one is refused", "[simd]") {
    CHECK(resolve_isa(Isa::automatic) == best_isa());
    CHECK(resolve_isa(Isa::scalar) == Isa::scalar);
    CHECK(supported_isas().front() == Isa::scalar);
    CHECK(parse_isa("avx2") == Isa::avx2);
    CHECK_THROWS_WITH(parse_isa("sse9"), Catch::Contains("--isa"));
    for (const Isa isa : {Isa::avx2, Isa::avx512})
        if (!isa_supported(isa)) CHECK_THROWS(resolve_isa(isa));
}

TEST_CASE("A one-ray stream visits the BVH as a stream of two copies of that ray does",
          "[stream][simd]") {
    // A one-ray stream's subtree runs in its own loop (traverse_one); the wide loop runs a
    // two-ray one. Same nodes and primitives in the same order, the same outcomes, so the
    // two-copy trace is the one-ray trace with every length and pass count doubled.
    struct OpSequence : TraceSink {
        std::vector<StreamOp> ops;  // slots and flags dropped: views die with the call
        void begin_pass(const TilePass&) override {}
        void op(const StreamOp& o) override {
            ops.push_back(
                StreamOp{o.kind, o.stage, o.generation, o.object, o.length, o.pass_count});
        }
        void end_pass(const TilePass&) override {}
    };
    const Scene s = test::box_scene(test::Variant::lights);
    const Bvh bvh(s);
    const CameraFrame camera(s.camera, 19, 17);
    uint64_t leaf_ops = 0, ops_checked = 0;
    for (uint32_t i = 0; i < 19 * 17; ++i) {
        Ray r = camera.generate({0, i, 0});
        auto coordinate = [&](uint32_t dim) {
            return float(random_bits(2, i, 0, 0, dim) >> 8) / 16777216.f - 0.5f;
        };
        if (i % 3 == 0) r.dir = Vec3(coordinate(0), coordinate(1), coordinate(2));
        if (i % 4 == 1) r.dir[i % 3] = -0.f;  // inv_dir -inf: the front-child vote's edge
        for (const Isa isa : supported_isas()) {
            INFO("ray " << i << " back end " << isa_name(isa));
            std::vector<Hit> one_hit, two_hits;
            OpSequence one, two;
            stream_intersect(bvh, {r}, one_hit, &one, isa);
            stream_intersect(bvh, {r, r}, two_hits, &two, isa);
            CHECK(std::memcmp(&one_hit[0], &two_hits[0], sizeof(Hit)) == 0);
            CHECK(std::memcmp(&one_hit[0], &two_hits[1], sizeof(Hit)) == 0);
            REQUIRE(one.ops.size() == two.ops.size());
            for (size_t k = 0; k < one.ops.size(); ++k) {
                INFO("op " << k);
                const StreamOp &a = one.ops[k], &b = two.ops[k];
                CHECK(a.kind == b.kind);
                CHECK(a.object == b.object);
                CHECK(a.length == 1);
                CHECK(b.length == 2);
                CHECK(2 * a.pass_count == b.pass_count);
                leaf_ops += a.kind != OpKind::box_test;
            }
            ops_checked += one.ops.size();
            // The counts-only path reports the same ops, tallied by kind and length
            // (ops_of_length).
            CountingSink counts({1});
            stream_intersect(bvh, {r}, one_hit, &counts, isa);
            uint64_t boxes = 0;
            for (const StreamOp& o : one.ops) boxes += o.kind == OpKind::box_test;
            CHECK(counts.kind_ops(OpKind::box_test) == boxes);
            CHECK(counts.stage(false, OpStage::traversal).passed == [&] {
                uint64_t p = 0;
                for (const StreamOp& o : one.ops)
                    if (o.kind == OpKind::box_test) p += o.pass_count;
                return p;
            }());
        }
    }
    CHECK(ops_checked > 5 * 19 * 17 * supported_isas().size());  // about 9 ops a ray
    CHECK(leaf_ops > 19 * 17);
}
