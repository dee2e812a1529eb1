// The workload trace: the counting sink's arithmetic, the Table 7 generalizations (tile 1 and
// width 1 is recursive tracing; width = stream size is packet tracing), the trace file.

#include <unistd.h>

#include <catch2/catch.hpp>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <map>

#include "base/input_error.h"
#include "kernels/bvh.h"
#include "kernels/camera.h"
#include "kernels/intersect.h"
#include "kernels/simd/isa.h"
#include "kernels/stream/stream_tracer.h"
#include "tests/kernels/count_checks.h"
#include "tests/temp_dir.h"
#include "workloads/scene_loader.h"

using namespace sfx;

namespace {

// A small scene with many primitives in a few clusters, triangles and spheres, no lights
// (so every ray is a closest-hit ray) or with a light (shadow rays too).
Scene cluster_scene(bool light) {
    Scene s;
    s.name = "clusters";
    Material diffuse;
    diffuse.diffuse = Vec3(0.6f);
    Material glossy;
    glossy.kind = MaterialKind::glossy;
    glossy.exponent = 20.f;
    Material lamp;
    lamp.emission = Vec3(5.f);
    s.materials = {diffuse, glossy, lamp};
    for (int i = 0; i < 120; ++i) {
        const float a = 0.37f * float(i), r = 0.4f + 0.012f * float(i);
        const Vec3 c(r * std::cos(a) * 2.f, -1.f + 0.015f * float(i), r * std::sin(a) * 2.f);
        const uint32_t b = uint32_t(s.positions.size());
        s.positions.insert(s.positions.end(),
                           {c, c + Vec3(0.3f, 0.05f, 0.f), c + Vec3(0.f, 0.3f, 0.1f)});
        s.triangles.push_back({b, b + 1, b + 2, uint32_t(i % 2)});
    }
    const uint32_t b = uint32_t(s.positions.size());
    s.positions.insert(s.positions.end(),
                       {{-4, -1.5f, -4}, {4, -1.5f, -4}, {4, -1.5f, 4}, {-4, -1.5f, 4}});
    s.triangles.push_back({b, b + 1, b + 2, 0});
    s.triangles.push_back({b, b + 2, b + 3, 0});
    for (int i = 0; i < 10; ++i)
        s.spheres.push_back({{-1.5f + 0.3f * float(i), 0.8f, -0.5f}, 0.14f, uint32_t(i % 2)});
    if (light) s.spheres.push_back({{0.f, 3.f, 0.f}, 0.5f, 2});
    s.environment = Vec3(0.5f);
    s.camera.eye = {0.f, 1.f, 5.f};
    s.camera.look_at = {0.f, -0.5f, 0.f};
    s.max_depth = 3;
    s.finalize();
    return s;
}

RenderSettings settings_for(const Scene& s, uint32_t size, uint32_t spp, uint32_t tile) {
    RenderSettings r;
    r.width = r.height = size;
    r.spp = spp;
    r.tile = tile;
    r.max_depth = s.max_depth;
    r.threads = 1;
    return r;
}

// Box and primitive tests of recursive tracing (and of packet tracing, below).
struct RecursiveCounts {
    uint64_t box = 0, prim = 0;
};
void count_recursive(const Bvh& bvh, const Ray& ray, RecursiveCounts& c) {
    TraversalCounts t;
    bvh.intersect(ray, t);
    c.box += t.boxes;
    c.prim += t.primitives;
}

// Masked packet traversal of all rays at once (packet tracing): one op per node the packet
// visits and per primitive of the leaves it reaches.
RecursiveCounts count_packet(const Bvh& bvh, const std::vector<Ray>& rays) {
    RecursiveCounts c;
    const size_t n = rays.size();
    std::vector<RayPrecomp> pre;
    std::vector<float> t(n);
    std::vector<Hit> hit(n);
    std::vector<uint8_t> root(n, 0);
    for (size_t i = 0; i < n; ++i) {
        Ray safe = rays[i];
        if (!ray_is_valid(safe)) safe.dir = {0.f, 0.f, 1.f};
        pre.emplace_back(safe);
        t[i] = rays[i].t_max;
        root[i] = ray_is_valid(rays[i]);
    }
    std::vector<std::pair<uint32_t, std::vector<uint8_t>>> stack{{0u, root}};
    while (!stack.empty()) {
        auto [index, mask] = std::move(stack.back());
        stack.pop_back();
        const BvhNode& node = bvh.nodes()[index];
        ++c.box;
        uint32_t active = 0, negative = 0;
        for (size_t i = 0; i < n; ++i) {
            if (!mask[i]) continue;
            mask[i] = intersect_box(pre[i], node.bounds, t[i]) != INFINITY;
            active += mask[i];
            negative += mask[i] && pre[i].dir[node.axis] < 0.f;
        }
        if (!active) continue;
        if (node.is_leaf()) {
            for (uint32_t j = node.first; j < node.first + node.count; ++j) {
                ++c.prim;
                for (size_t i = 0; i < n; ++i)
                    if (mask[i] && bvh.intersect_primitive(pre[i], bvh.prim_ids()[j], t[i], hit[i]))
                        t[i] = hit[i].t;
            }
        } else {
            const bool right_first = 2 * negative > active;
            stack.push_back({right_first ? BvhNode::left(index) : node.right(), mask});
            stack.push_back({right_first ? node.right() : BvhNode::left(index), mask});
        }
    }
    return c;
}

struct RayCollector : RayObserver {
    std::vector<Ray> rays;
    void ray(const PathState&, const Ray& r, const Hit&, bool) override { rays.push_back(r); }
};

std::string read_file(const std::string& path) {
    std::ifstream in(path, std::ios::binary);
    return {std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
}

}  // namespace

TEST_CASE("Counting sink: utilization = sum len / (N * sum ceil(len / N)) per stage", "[stream]") {
    CountingSink sink({1, 4, 16});
    std::vector<uint32_t> slots(40);
    std::vector<uint8_t> passed(40, 1);
    for (uint32_t i = 0; i < 40; ++i) slots[i] = i;
    auto op = [&](OpKind kind, uint16_t generation, uint32_t len, uint32_t pass) {
        sink.op(StreamOp{kind, stage_of(kind), generation, 1, len, pass, slots.data(),
                         passed.data()});
    };
    sink.begin_pass({});
    op(OpKind::box_test, 1, 5, 3);
    op(OpKind::box_test, 1, 16, 16);
    op(OpKind::box_test, 1, 17, 2);
    op(OpKind::triangle_test, 0, 3, 1);
    op(OpKind::box_test, 0, 40, 40);
    op(OpKind::sphere_test, 6, 4, 1);
    sink.end_pass({});
    const auto& t = sink.stage(true, OpStage::traversal);
    CHECK(t.ops == 3);
    CHECK(t.lanes == 38);
    CHECK(t.passed == 21);
    CHECK(t.groups[1] == 2 + 4 + 5);  // width 4
    CHECK(t.groups[2] == 1 + 1 + 2);  // width 16
    CHECK(t.utilization(0, 1) == 1.0);
    CHECK(t.utilization(1, 4) == Approx(38.0 / 44.0));
    CHECK(t.utilization(2, 16) == Approx(38.0 / 64.0));
    CHECK(t.average_length() == Approx(38.0 / 3.0));
    CHECK(t.histogram[2] == 1);  // 5 in [4, 8)
    CHECK(t.histogram[4] == 2);  // 16, 17 in [16, 32)
    CHECK(sink.stage(false, OpStage::intersection).utilization(2, 16) == Approx(3.0 / 16.0));
    CHECK(sink.stage(false, OpStage::traversal).lanes == 40);
    CHECK(sink.stage(true, OpStage::shading).ops == 0);
    CHECK(sink.kind_ops(OpKind::box_test) == 4);
    // Each generation's first box test is its entry test, one lane per ray: 5 + 40.
    CHECK(sink.rays() == 45);
    CHECK(sink.rays(false) == 40);
    CHECK(sink.rays(true) == 5);
    CHECK(sink.kind_lanes(OpKind::box_test) == 78);
    CHECK(sink.kind_lanes(OpKind::box_test, false) == 40);
    CHECK(sink.kind_lanes(OpKind::box_test, true) == 38);
    CHECK(sink.kind_ops(OpKind::sphere_test) == 1);
    // Per bounce: generation 0, 1, and the last slot for generation 6.
    CHECK(sink.bounce(0).rays == 40);
    CHECK(sink.bounce(0).box_lanes == 40);
    CHECK(sink.bounce(0).prim_ops == 1);
    CHECK(sink.bounce(0).prim_lanes == 3);
    CHECK(sink.bounce(1).rays == 5);
    CHECK(sink.bounce(1).box_ops == 3);
    CHECK(sink.bounce(1).box_lanes == 38);
    CHECK(sink.bounce(1).prim_ops == 0);
    CHECK(sink.bounce(6).prim_ops == 1);  // a sphere test counts as a primitive test
    CHECK(sink.bounce(6).prim_lanes == 4);
    CHECK(sink.bounce(CountingSink::k_bounce_slots - 1).prim_lanes == 4);
}

TEST_CASE("Counting sink: ops_of_length adds what as many op() calls add", "[stream]") {
    // `batched` takes the sink's own ops_of_length; `single` the base class's, which calls op()
    // once per op. A generation's first op is among the batched ones (its entry test).
    CountingSink batched({1, 8, 12, 16}), single({1, 8, 12, 16});
    auto both = [&](OpKind kind, uint16_t generation, uint32_t length, uint32_t count,
                    uint32_t passed) {
        batched.ops_of_length(kind, stage_of(kind), generation, length, count, passed, 0);
        single.TraceSink::ops_of_length(kind, stage_of(kind), generation, length, count, passed, 0);
    };
    auto op = [&](OpKind kind, uint16_t generation, uint32_t len, uint32_t pass) {
        const StreamOp o{kind, stage_of(kind), generation, k_no_object, len, pass};
        batched.op(o);
        single.op(o);
    };
    for (CountingSink* s : {&batched, &single}) s->begin_pass({});
    both(OpKind::box_test, 0, 1, 7, 4);
    op(OpKind::box_test, 0, 30, 12);
    both(OpKind::box_test, 0, 13, 3, 20);  // lengths 13 and 30 differ in groups and buckets
    both(OpKind::triangle_test, 0, 1, 5, 2);
    both(OpKind::triangle_test, 0, 17, 2, 3);
    both(OpKind::sphere_test, 0, 1, 0, 0);
    op(OpKind::box_test, 1, 9, 9);
    both(OpKind::box_test, 1, 1, 11, 0);
    both(OpKind::box_test, 2, 5, 3, 15);
    both(OpKind::sphere_test, 4, 64, 6, 1);
    for (CountingSink* s : {&batched, &single}) s->end_pass({});

    CHECK(batched.rays() == 1 + 9 + 5);  // each generation's first box test: its lanes
    CHECK(batched.kind_ops(OpKind::box_test) == 7 + 1 + 3 + 1 + 11 + 3);
    test::check_same_counts(batched, single);
}

namespace {
// Checks each triangle op of a pass against the rays it tested: its passing lanes and failed
// candidates are the lanes whose ray's line the float edge stage does not reject. A
// generation's traversal ops come before its rays are observed, and those before its shading
// ops, so a generation's triangle ops are checked at its first shading op.
struct CandidateCheck : TraceSink, RayObserver {
    const Scene& scene;
    uint32_t width = 0, x0 = 0, y0 = 0, tile_width = 0;
    std::vector<StreamOp> pending;
    std::vector<std::vector<uint32_t>> pending_slots;
    std::map<uint32_t, Ray> rays;  // by slot, this generation's
    uint64_t ops = 0, mismatches = 0, failed[2] = {0, 0}, passed[2] = {0, 0};
    CandidateCheck(const Scene& s, uint32_t w) : scene(s), width(w) {}
    void begin_pass(const TilePass& p) override { x0 = p.x0, y0 = p.y0, tile_width = p.x1 - p.x0; }
    void op(const StreamOp& o) override {
        if (o.kind != OpKind::triangle_test) {
            if (o.kind != OpKind::box_test && o.kind != OpKind::sphere_test) check();
            CHECK(o.failed_candidates == 0);
            return;
        }
        pending.push_back(o);
        pending_slots.emplace_back(o.slots, o.slots + o.length);
    }
    void ray(const PathState& p, const Ray& r, const Hit&, bool) override {
        const uint32_t px = p.key.pixel % width, py = p.key.pixel / width;
        rays[(py - y0) * tile_width + (px - x0)] = r;
    }
    void end_pass(const TilePass&) override { check(); }
    void check() {
        for (size_t k = 0; k < pending.size(); ++k) {
            const StreamOp& o = pending[k];
            const Triangle& t = scene.triangles[o.object];
            const Vec3 &p0 = scene.positions[t.v0], &p1 = scene.positions[t.v1],
                       &p2 = scene.positions[t.v2];
            uint32_t candidates = 0;
            for (uint32_t slot : pending_slots[k]) {
                const RayPrecomp r(rays.at(slot));
                const float org[3] = {r.org.x, r.org.y, r.org.z};
                candidates += !edges_reject<1>(
                    shear_triangle<1>(org, r.kx, r.ky, r.kz, r.sx, r.sy, p0, p1, p2));
            }
            ++ops;
            mismatches += candidates != o.pass_count + o.failed_candidates;
            failed[o.generation > 0] += o.failed_candidates;
            passed[o.generation > 0] += o.pass_count;
        }
        pending.clear();
        pending_slots.clear();
        rays.clear();
    }
};
}  // namespace

TEST_CASE("A triangle op's failed candidates are the lanes its float stage keeps that miss",
          "[stream]") {
    // Cornell's walls are quads, each ray's line crossing one of their two triangles: a primary
    // ray's candidates take their hit, a secondary ray's fail on its own surface's leaf (behind
    // its origin) and on leaves beyond its hit.
    const Scene s = load_scene("cornell");
    const Bvh bvh(s);
    for (const Isa isa : supported_isas()) {
        INFO("back end " << isa_name(isa));
        RenderSettings r = settings_for(s, 16, 1, 8);
        r.isa = isa;
        StreamTracer tracer(s, bvh, r);
        CandidateCheck check(s, r.width);
        RenderStats stats;
        std::vector<Vec3> sums(64);
        const std::vector<TileRect> tiles = make_tiles(r.width, r.height, r.tile);
        for (uint32_t i = 0; i < tiles.size(); ++i)
            tracer.trace_pass(tiles[i], i, 0, sums.data(), stats, &check, &check);
        CHECK(check.ops > 0);
        CHECK(check.mismatches == 0);
        CHECK(check.failed[0] < check.passed[0] / 10);
        CHECK(check.failed[1] > check.passed[1]);
    }
}

TEST_CASE("Table 7: tile 1 and width 1 give recursive tracing's op counts", "[stream]") {
    const Scene s = cluster_scene(false);
    const Bvh bvh(s);
    const RenderSettings r = settings_for(s, 16, 2, 1);
    StreamTracer tracer(s, bvh, r);
    CountingSink sink({1});
    RayCollector rays;
    RenderStats stats;
    const std::vector<TileRect> tiles = make_tiles(r.width, r.height, 1);
    for (uint32_t t = 0; t < tiles.size(); ++t)
        for (uint32_t smp = 0; smp < r.spp; ++smp) {
            Vec3 sum;
            tracer.trace_pass(tiles[t], t, smp, &sum, stats, &sink, &rays);
        }
    RecursiveCounts c;
    for (const Ray& ray : rays.rays) count_recursive(bvh, ray, c);
    REQUIRE(stats.extension_rays > 100);
    CHECK(rays.rays.size() == stats.rays());
    CHECK(sink.kind_ops(OpKind::box_test) == c.box);
    CHECK(sink.kind_ops(OpKind::triangle_test) + sink.kind_ops(OpKind::sphere_test) == c.prim);
    for (bool secondary : {false, true})
        for (OpStage st : {OpStage::traversal, OpStage::intersection}) {
            CHECK(sink.stage(secondary, st).utilization(0, 1) == 1.0);  // every op one lane
            CHECK(sink.stage(secondary, st).lanes == sink.stage(secondary, st).ops);
        }
}

TEST_CASE("Table 7: width equal to the stream size gives packet tracing's op counts", "[stream]") {
    const Scene s = cluster_scene(false);
    const Bvh bvh(s);
    for (uint32_t tile : {4u, 16u}) {
        const uint32_t size = tile * tile;
        // The camera rays of one tile pass, and a set of diffuse-like secondary rays.
        const CameraFrame camera(s.camera, 64, 64);
        std::vector<Ray> primary, secondary;
        for (uint32_t y = 20; y < 20 + tile; ++y)
            for (uint32_t x = 20; x < 20 + tile; ++x)
                primary.push_back(camera.generate({0, y * 64 + x, 0}));
        for (uint32_t i = 0; i < size; ++i) {
            Ray ray;
            ray.org = {0.1f * float(i % 7) - 0.3f, -1.4f, 0.1f * float(i % 5)};
            const float u = random_float(3, i, 0, 1, RngDim::direction_u);
            const float v = random_float(3, i, 0, 1, RngDim::direction_v);
            ray.dir = to_world(sample_cosine_hemisphere(u, v), {0.f, 1.f, 0.f});
            secondary.push_back(ray);
        }
        for (const std::vector<Ray>* rays : {&primary, &secondary}) {
            CountingSink sink({size});
            std::vector<Hit> hits;
            stream_intersect(bvh, *rays, hits, &sink);
            const RecursiveCounts packet = count_packet(bvh, *rays);
            INFO("tile " << tile);
            CHECK(sink.stage(false, OpStage::traversal).groups[0] == packet.box);
            CHECK(sink.stage(false, OpStage::intersection).groups[0] == packet.prim);
            CHECK(sink.stage(false, OpStage::traversal).utilization(0, size) < 1.0);
        }
    }
}

TEST_CASE("Trace file: round trip, and the same bytes for 1 and 2 threads", "[stream]") {
    const Scene s = cluster_scene(true);
    const Bvh bvh(s);
    RenderSettings r = settings_for(s, 24, 2, 8);
    const std::vector<uint32_t> widths{4, 8, 16};
    CountingSink direct(widths);
    const RenderResult a = render_stream(s, bvh, r, &direct);
    // The failed candidates the tracer tallies for a counts-only sink (ops_of_length), and
    // below the ones each op of the file carries; and the ops that start a traversal.
    struct FailedCandidates : TraceSink {
        bool counts = true;
        uint64_t sum = 0, starts = 0, box_calls = 0, starts_not_box = 0;
        uint64_t shared = 0, shared_camera = 0, shared_not_start = 0;
        void op(const StreamOp& o) override {
            sum += o.failed_candidates;
            starts += o.starts_traversal;
            shared += o.origin_shared;
            shared_camera += o.origin_shared && o.generation == 0 && o.length > 1;
            shared_not_start += o.origin_shared && !o.starts_traversal;
            box_calls += o.kind == OpKind::box_test;
            starts_not_box += o.starts_traversal && o.kind != OpKind::box_test;
        }
        void ops_of_length(OpKind, OpStage, uint16_t, uint32_t, uint32_t, uint32_t,
                           uint32_t failed_candidates) override {
            sum += failed_candidates;
        }
        bool counts_only() const override { return counts; }
    } tallied, from_file;
    render_stream(s, bvh, r, &tallied);
    CHECK(tallied.sum > 0);
    CHECK(direct.passes() == 9 * 2);
    CHECK(direct.rays() == a.stats.rays());
    CHECK(direct.kind_ops(OpKind::shadow_filter) > 0);

    // In the temporary directory, named by process, so parallel test runs never share a file.
    const std::string base = (std::filesystem::temp_directory_path() /
                              ("sfx_stream_trace_" + std::to_string(::getpid())))
                                 .string();
    const std::string p1 = base + "_1.trc", p2 = base + "_2.trc";
    {
        TraceFileWriter w(p1);
        render_stream(s, bvh, r, &w);
    }
    r.threads = 2;
    {
        TraceFileWriter w(p2);
        render_stream(s, bvh, r, &w);
    }
    const std::string b1 = read_file(p1), b2 = read_file(p2);
    CHECK(b1.size() > 1000);
    CHECK(b1 == b2);

    from_file.counts = false;
    read_trace_file(p1, from_file);
    CHECK(from_file.sum == tallied.sum);
    // A counts-only sink gets each traversal's first op alone (OpTally) and the rest of its box
    // tests as tallies: its box-test calls count the traversals, and each starts one; the file
    // flags as many of its box tests, and nothing else.
    CHECK(tallied.box_calls > 0);
    CHECK(tallied.starts == tallied.box_calls);
    CHECK(from_file.starts == tallied.box_calls);
    CHECK(from_file.box_calls > 3 * from_file.starts);
    CHECK(from_file.starts_not_box == 0);
    // The camera's rays share its pinhole: their traversals are flagged, in the file as in the
    // tracer's own tally, and only on ops that start a traversal; bounces' are not all.
    CHECK(tallied.shared_camera > 0);
    CHECK(from_file.shared == tallied.shared);
    CHECK(from_file.shared_camera == tallied.shared_camera);
    CHECK(from_file.shared < from_file.starts);
    CHECK(from_file.shared_not_start == 0);
    CountingSink replayed(widths);
    const TraceHeader h = read_trace_file(p1, replayed);
    CHECK(h.scene_hash == scene_hash(s));
    CHECK(h.tile == 8);
    CHECK(h.spp == 2);
    CHECK(replayed.passes() == direct.passes());
    CHECK(replayed.generations() == direct.generations());
    // The direct counts took the tracer's lane-free path (CountingSink::counts_only); the file
    // was written with every slot and pass flag: the same ops either way.
    CHECK(direct.counts_only());
    test::check_same_counts(replayed, direct);
    std::remove(p1.c_str());
    std::remove(p2.c_str());
    // A truncated file is an error, not a silent partial trace.
    {
        std::ofstream out(p1, std::ios::binary);
        out << b1.substr(0, b1.size() / 2);
    }
    CountingSink partial(widths);
    CHECK_THROWS(read_trace_file(p1, partial));
    // A traversal-start byte of 2 (a shared origin without a start) is refused. The first op
    // follows the header (magic, version, scene hash, the frame's fields) and the first pass
    // record (u8 and seven u32); its flag byte follows u8 kind, stage, u16 generation and four
    // u32.
    size_t frame_bytes = 0;
    TraceFrame frame = r;
    frame.visit([&](auto& field) { frame_bytes += sizeof field; });
    const size_t op_at = 8 + 4 + 8 + frame_bytes + 1 + 7 * 4,
                 flag_at = op_at + 1 + 1 + 1 + 2 + 4 * 4;
    REQUIRE(b1.size() > flag_at);
    REQUIRE(b1[op_at] == 'O');
    CHECK(b1[flag_at] == 0);  // the camera's op starts no traversal
    std::string bad = b1;
    bad[flag_at] = 2;
    {
        std::ofstream out(p1, std::ios::binary);
        out << bad;
    }
    CountingSink refused(widths);
    CHECK_THROWS_WITH(read_trace_file(p1, refused),
                      Catch::Matchers::Contains("a traversal-start flag that is not 0, 1 or 3"));
    std::remove(p1.c_str());
}

namespace {
// A trace file by hand: the header of a 4x4 frame, one pass over all of it (16 slots), one
// op of `length` lanes with the given slots, pass count and pass bits, then the rest.
template <class T>
void put(std::string& b, T v) {
    b.append(reinterpret_cast<const char*>(&v), sizeof v);
}
std::string crafted_trace(uint32_t slot_count, uint32_t length, uint32_t pass_count,
                          const std::vector<uint32_t>& slots, uint8_t bits, bool finish = true) {
    std::string b = "SFXTRACE";
    put(b, uint32_t(1));  // a version-1 header (read still): no seed-paper options
    put(b, uint64_t(7));
    for (uint32_t v : {4u, 4u, 1u, 4u, 3u}) put(b, v);  // width height spp tile max_depth
    put(b, uint64_t(0));
    b += 'P';
    for (uint32_t v : {0u, 0u, 0u, 4u, 4u, 0u, slot_count}) put(b, v);
    b += 'O';
    b += char(OpKind::box_test);
    b += char(OpStage::traversal);
    put(b, uint16_t(0));
    put(b, uint32_t(0));
    put(b, length);
    put(b, pass_count);
    for (uint32_t s : slots) put(b, s);
    if (length > 0) b += char(bits);
    if (finish) {
        b += 'E';
        put(b, uint32_t(1));
        b += 'F';
    }
    return b;
}
}  // namespace

TEST_CASE("Trace file version 6: the header carries the whole frame, the seed papers' options too",
          "[stream]") {
    const Scene s = cluster_scene(true);
    const Bvh bvh(s);
    RenderSettings r = settings_for(s, 16, 1, 8);
    r.primary_entry = PrimaryEntry::aepsa;
    r.reorder = RayReorder::hit_point;
    r.reorder_lod_ppm = 5000;
    r.batching = RayBatching::raygrid;
    r.batching_queue = 8;
    r.batching_cell_prims = 64;
    TempDir dir("trace_v3");
    const std::string path = (dir.path / "frame.trc").string();
    {
        TraceFileWriter w(path);
        render_stream(s, bvh, r, &w);
    }
    CountingSink sink({8});
    const TraceHeader h = read_trace_file(path, sink);
    CHECK(h.version == 6);
    CHECK(h.width == r.width);
    CHECK(h.height == r.height);
    CHECK(h.spp == r.spp);
    CHECK(h.tile == r.tile);
    CHECK(h.max_depth == r.max_depth);
    CHECK(h.seed == r.seed);
    CHECK(h.primary_entry == PrimaryEntry::aepsa);
    CHECK(h.reorder == RayReorder::hit_point);
    CHECK(h.reorder_lod_ppm == 5000);
    CHECK(h.batching == RayBatching::raygrid);
    CHECK(h.batching_queue == 8);
    CHECK(h.batching_cell_prims == 64);
    CHECK(sink.kind_ops(OpKind::frustum_test) > 0);
    CHECK(sink.kind_ops(OpKind::reorder_key) > 0);
    CHECK(sink.kind_ops(OpKind::raygrid_enqueue) > 0);
}

TEST_CASE("Trace file version 2 still reads: batching at its defaults", "[stream]") {
    std::string b = "SFXTRACE";
    put(b, uint32_t(2));
    put(b, uint64_t(7));
    for (uint32_t v : {4u, 4u, 1u, 4u, 3u}) put(b, v);  // width height spp tile max_depth
    put(b, uint64_t(0));                                // seed
    b += char(PrimaryEntry::aepsa);
    b += char(RayReorder::hit_point);
    put(b, uint32_t(5000));  // reorder_lod_ppm: the last field of version 2
    b += 'F';
    const TempDir dir("sfx-trace-v2");
    const std::string path = (dir.path / "v2.trc").string();
    std::ofstream(path, std::ios::binary) << b;
    CountingSink sink({8});
    const TraceHeader h = read_trace_file(path, sink);
    CHECK(h.version == 2);
    CHECK(h.reorder == RayReorder::hit_point);
    CHECK(h.reorder_lod_ppm == 5000);
    CHECK(h.batching == RayBatching::none);
    CHECK(h.batching_queue == TraceFrame{}.batching_queue);
}

TEST_CASE("Trace file: a damaged file is an InputError naming the byte, never a huge allocation",
          "[stream]") {
    const TempDir dir("sfx-trace-reader");
    const std::string path = (dir.path / "t.trc").string();
    auto read = [&](const std::string& bytes) {
        std::ofstream(path, std::ios::binary) << bytes;
        CountingSink sink({8});
        read_trace_file(path, sink);
    };
    read(crafted_trace(16, 2, 1, {3, 15}, 0b01));  // the well-formed version of each case below
    using Catch::Matchers::Contains;
    CHECK_THROWS_WITH(read(crafted_trace(16, 2, 1, {3, 16}, 0b01)),
                      Contains("a ray slot past its tile pass"));
    CHECK_THROWS_WITH(read(crafted_trace(16, 2, 2, {3, 15}, 0b01)), Contains("pass count"));
    CHECK_THROWS_WITH(read(crafted_trace(17, 2, 1, {3, 15}, 0b01)),
                      Contains("slot count is not its pixel count"));
    // A length the pass allows but the file cannot hold: refused before allocating 16 GiB.
    CHECK_THROWS_WITH(read(crafted_trace(0xffffffffu, 0xfffffff0u, 0, {}, 0)),
                      Contains("slot count"));
    CHECK_THROWS_WITH(read(crafted_trace(16, 16, 0, {}, 0)), Contains("truncated (at byte"));
    CHECK_THROWS_WITH(read(crafted_trace(16, 2, 1, {3, 15}, 0b01, false)), Contains("truncated"));
    CHECK_THROWS_WITH(read(crafted_trace(16, 2, 1, {3, 15}, 0b01) + "x"),
                      Contains("bytes after the end"));
    CHECK_THROWS_AS(read("SFXTRACE"), InputError);
}
