// The seed papers' alternatives as stream-tracer options: each leaves the image bit-identical,
// appears in the trace as its own kinds of op, and only when it is on.

#include <unistd.h>

#include <catch2/catch.hpp>
#include <cstring>
#include <filesystem>
#include <fstream>

#include "hw_model/workload_shape.h"
#include "kernels/bvh.h"
#include "kernels/stream/entry_point.h"
#include "kernels/stream/hit_point_reorder.h"
#include "kernels/stream/ray_grid.h"
#include "kernels/stream/stream_tracer.h"
#include "tests/kernels/test_scenes.h"

using namespace sfx;

namespace {

bool same_bits(const Image& a, const Image& b) {
    return a.width == b.width && a.height == b.height &&
           std::memcmp(a.pixels.data(), b.pixels.data(), a.pixels.size() * sizeof(Vec3)) == 0;
}

RenderSettings settings_for(const Scene& s, uint32_t w, uint32_t h, uint32_t spp, uint32_t tile) {
    RenderSettings r;
    r.width = w;
    r.height = h;
    r.spp = spp;
    r.max_depth = s.max_depth;
    r.tile = tile;
    r.threads = 2;
    return r;
}

// Counts, and per pass and generation the slot order of the stream's first box test.
struct OrderSink : CountingSink {
    std::vector<std::vector<uint32_t>> entry_orders;
    int32_t generation = -1;
    OrderSink() : CountingSink({8}) {}
    bool counts_only() const override { return false; }  // it reads the slots
    void begin_pass(const TilePass& p) override {
        CountingSink::begin_pass(p);
        generation = -1;
    }
    void op(const StreamOp& o) override {
        CountingSink::op(o);
        if (o.kind != OpKind::box_test || int32_t(o.generation) == generation) return;
        generation = o.generation;
        entry_orders.emplace_back(o.slots, o.slots + o.length);
    }
};

struct Run {
    RenderResult result;
    OrderSink counts;
};

Run run(const Scene& s, const Bvh& bvh, RenderSettings r) {
    Run out;
    r.threads = 1;  // the order sink needs passes in order
    out.result = render_stream(s, bvh, r, &out.counts);
    return out;
}

// A wall of small spheres seen head on (thin lens): a small tile's frustum overlaps a few of
// them, so its entry point lies well below the root. (Enclosing walls would not allow that:
// every frustum overlaps them.)
Scene sphere_wall() {
    Scene s = test::box_scene(test::Variant::environment_only);
    s.name = "sphere wall";
    s.triangles.clear();
    s.positions.clear();
    s.spheres.clear();
    for (int i = 0; i < 12; ++i)
        for (int j = 0; j < 12; ++j)
            s.spheres.push_back({{-1.65f + 0.3f * float(i), -1.65f + 0.3f * float(j), 0.f},
                                 0.12f,
                                 uint32_t((i + j) % 2 ? 0 : 4)});
    s.camera.eye = {0.f, 0.f, 4.5f};
    std::vector<uint32_t> groups(s.primitive_count());
    for (uint32_t p = 0; p < groups.size(); ++p) groups[p] = p;
    s.finalize(groups);
    return s;
}

}  // namespace

TEST_CASE("Frustum proxy: a box any of its rays enters overlaps, boxes off to one side do not",
          "[stream][seeds]") {
    std::vector<RayPrecomp> rays;
    for (float x : {-0.1f, 0.1f})
        for (float y : {-0.1f, 0.1f}) {
            Ray r;
            r.org = {0.f, 0.f, 0.f};
            r.dir = normalize(Vec3(x, y, -1.f));
            rays.emplace_back(r);
        }
    FrustumProxy f;
    f.build(uint32_t(rays.size()), [&](uint32_t i) -> const RayPrecomp& { return rays[i]; });
    CHECK(f.overlaps({{-0.5f, -0.5f, -6.f}, {0.5f, 0.5f, -5.f}}));      // straight ahead
    CHECK(f.overlaps({{0.55f, -0.1f, -6.f}, {0.7f, 0.1f, -5.f}}));      // the edge of the cone
    CHECK_FALSE(f.overlaps({{2.f, -0.5f, -6.f}, {3.f, 0.5f, -5.f}}));   // right of it
    CHECK_FALSE(f.overlaps({{-0.5f, -0.5f, 1.f}, {0.5f, 0.5f, 2.f}}));  // behind the origin
    FrustumProxy none;
    none.build(0, [&](uint32_t i) -> const RayPrecomp& { return rays[i]; });
    CHECK_FALSE(none.overlaps({{-1.f, -1.f, -1.f}, {1.f, 1.f, 1.f}}));
}

TEST_CASE("AEPSA: the image is bit-identical to root entry, traversal starts deeper",
          "[stream][seeds]") {
    for (const Scene& s : {test::box_scene(test::Variant::lights), sphere_wall(),
                           test::box_scene(test::Variant::environment_only)}) {
        const Bvh bvh(s);
        for (uint32_t tile : {4u, 8u, 16u}) {
            RenderSettings r = settings_for(s, 32, 24, 2, tile);
            const Run root = run(s, bvh, r);
            r.primary_entry = PrimaryEntry::aepsa;
            const Run aepsa = run(s, bvh, r);
            INFO("scene " << s.name << " tile " << tile);
            CHECK(same_bits(root.result.image, aepsa.result.image));
            CHECK(root.result.stats.rays() == aepsa.result.stats.rays());
            CHECK(root.counts.rays() == aepsa.counts.rays());
            // Only with the option: its own kinds, one search per pass.
            CHECK(root.counts.kind_ops(OpKind::frustum_bounds) == 0);
            CHECK(root.counts.kind_ops(OpKind::frustum_test) == 0);
            CHECK(root.result.stats.entry_searches == 0);
            CHECK(aepsa.counts.kind_ops(OpKind::frustum_bounds) == aepsa.counts.passes());
            CHECK(aepsa.counts.kind_ops(OpKind::frustum_test) > 0);
            CHECK(aepsa.result.stats.entry_searches == aepsa.counts.passes());
            // Entering below the root skips box tests; it never adds any.
            CHECK(aepsa.counts.kind_lanes(OpKind::box_test) <=
                  root.counts.kind_lanes(OpKind::box_test));
            // Secondary rays are untouched.
            CHECK(aepsa.counts.stage(true, OpStage::traversal).lanes ==
                  root.counts.stage(true, OpStage::traversal).lanes);
        }
    }
}

TEST_CASE("AEPSA: small tiles of a close view enter below the root and save box tests",
          "[stream][seeds]") {
    const Scene s = sphere_wall();
    const Bvh bvh(s);
    RenderSettings r = settings_for(s, 32, 32, 1, 4);
    const Run root = run(s, bvh, r);
    r.primary_entry = PrimaryEntry::aepsa;
    const Run aepsa = run(s, bvh, r);
    CHECK(aepsa.result.stats.entry_depth_sum > 0);
    CHECK(aepsa.counts.stage(false, OpStage::traversal).lanes -
              aepsa.counts.kind_lanes(OpKind::frustum_bounds) -
              aepsa.counts.kind_lanes(OpKind::frustum_test) <
          root.counts.stage(false, OpStage::traversal).lanes);
}

TEST_CASE("Workload shape: frustum units exist only when the workload searches entry points",
          "[stream][seeds]") {
    WorkloadShape shape;
    shape.features = test::box_scene(test::Variant::lights).features();
    CHECK_FALSE(shape.needed_kinds()[size_t(OpKind::frustum_test)]);
    CHECK_FALSE(shape.needed_kinds()[size_t(OpKind::frustum_bounds)]);
    shape.primary_entry_aepsa = true;
    CHECK(shape.needed_kinds()[size_t(OpKind::frustum_test)]);
    CHECK(shape.needed_kinds()[size_t(OpKind::frustum_bounds)]);
}

TEST_CASE("Hit-point reorder: proxies at the fraction asked, keys on a two-level Z-curve",
          "[stream][seeds]") {
    const Scene s = test::box_scene(test::Variant::lights);
    const Bvh bvh(s);
    const uint64_t prims = s.primitive_count();
    const HitPointReorder all(bvh, 1000000);  // every primitive its own proxy: the leaves
    CHECK(all.proxies() == bvh.stats().leaves);
    const HitPointReorder tenth(bvh, 100000);  // proxies of at most 10 primitives
    CHECK(tenth.proxies() >= prims / 10);
    CHECK(tenth.proxies() < all.proxies());
    const Bounds3 b = bvh.nodes()[0].bounds;
    CHECK(all.key(b.lo) == 0);
    // The high level decides first: a point in a later high-level cell sorts after any point
    // of an earlier one, whatever its low-level cell.
    const Vec3 e = b.extent();
    const Vec3 late_low = b.lo + Vec3(e.x * (1.f / 64.f) * 0.99f, 0.f, 0.f);
    const Vec3 next_high = b.lo + Vec3(e.x * (1.f / 64.f) * 1.01f, 0.f, 0.f);
    CHECK(all.key(late_low) < all.key(next_high));
    CHECK(all.key(late_low) < (uint64_t(1) << 18));
    CHECK(all.key(next_high) == (uint64_t(1) << 18) + 0);
}

TEST_CASE(
    "Hit-point reorder: the image is bit-identical, streams are sorted, traversal visits "
    "the same nodes",
    "[stream][seeds]") {
    for (const Scene& s : {test::box_scene(test::Variant::lights), sphere_wall()}) {
        const Bvh bvh(s);
        RenderSettings r = settings_for(s, 32, 24, 2, 16);
        const Run plain = run(s, bvh, r);
        r.reorder = RayReorder::hit_point;
        const Run sorted = run(s, bvh, r);
        r.primary_entry = PrimaryEntry::aepsa;
        const Run both = run(s, bvh, r);
        INFO("scene " << s.name);
        CHECK(same_bits(plain.result.image, sorted.result.image));
        CHECK(same_bits(plain.result.image, both.result.image));
        for (OpKind k : {OpKind::reorder_lod_test, OpKind::reorder_key, OpKind::reorder_sort}) {
            CHECK(plain.counts.kind_ops(k) == 0);
            CHECK(sorted.counts.kind_ops(k) > 0);
        }
        CHECK(sorted.counts.kind_ops(OpKind::frustum_test) == 0);
        CHECK(both.counts.kind_ops(OpKind::frustum_test) > 0);
        // One key op per generation that has two or more rays; the streams differ in order.
        CHECK(sorted.counts.kind_ops(OpKind::reorder_key) <= sorted.counts.generations());
        REQUIRE(plain.counts.entry_orders.size() == sorted.counts.entry_orders.size());
        size_t reordered = 0;
        for (size_t i = 0; i < plain.counts.entry_orders.size(); ++i) {
            std::vector<uint32_t> a = plain.counts.entry_orders[i],
                                  b = sorted.counts.entry_orders[i];
            reordered += a != b;
            std::sort(a.begin(), a.end());
            std::sort(b.begin(), b.end());
            CHECK(a == b);  // the same rays
        }
        CHECK(reordered > 0);
        // Stream filtering tests whole streams against nodes: the order of a stream changes
        // neither which nodes and primitives are tested nor how many lanes.
        for (OpKind k : {OpKind::box_test, OpKind::triangle_test, OpKind::sphere_test}) {
            CHECK(sorted.counts.kind_ops(k) == plain.counts.kind_ops(k));
            CHECK(sorted.counts.kind_lanes(k) == plain.counts.kind_lanes(k));
        }
    }
}

TEST_CASE("Workload shape: reorder units exist only when the workload reorders",
          "[stream][seeds]") {
    WorkloadShape shape;
    shape.features = test::box_scene(test::Variant::lights).features();
    for (OpKind k : {OpKind::reorder_lod_test, OpKind::reorder_key, OpKind::reorder_sort})
        CHECK_FALSE(shape.needed_kinds()[size_t(k)]);
    shape.reorder_hit_point = true;
    for (OpKind k : {OpKind::reorder_lod_test, OpKind::reorder_key, OpKind::reorder_sort})
        CHECK(shape.needed_kinds()[size_t(k)]);
    CHECK_FALSE(shape.needed_kinds()[size_t(OpKind::frustum_test)]);
}

TEST_CASE("RayGrid: the cut's cells hold every primitive once, none more than asked",
          "[stream][seeds]") {
    const Scene s = test::box_scene(test::Variant::lights);
    const Bvh bvh(s);
    const BvhNodes& nodes = bvh.nodes();
    for (uint32_t cell_prims : {1u, 4u, 16u, 1000000u}) {
        const RayGrid grid(bvh, cell_prims);
        INFO("cell_prims " << cell_prims);
        uint64_t held = 0;
        for (uint32_t c = 0; c < grid.cell_count(); ++c) {
            const uint32_t node = grid.cell_node(c);
            CHECK(grid.cell_of(node) == c);
            CHECK((c == 0 || grid.cell_node(c - 1) < node));  // cells in node order
            // The subtree's primitives: its leaves lie in [node, next node outside it).
            uint64_t prims = 0;
            std::vector<uint32_t> stack = {node};
            while (!stack.empty()) {
                const BvhNode& n = nodes[stack.back()];
                const uint32_t i = stack.back();
                stack.pop_back();
                if (n.is_leaf()) {
                    prims += n.count;
                } else {
                    stack.push_back(BvhNode::left(i));
                    stack.push_back(n.right());
                }
            }
            CHECK((prims <= cell_prims || nodes[node].is_leaf()));
            held += prims;
        }
        CHECK(held == s.primitive_count());
        if (cell_prims >= s.primitive_count()) {
            CHECK(grid.cell_count() == 1);  // the root is the one cell
            CHECK(grid.top_nodes() == 0);
        } else {
            CHECK(grid.cell_count() > 1);
            CHECK(grid.top_nodes() + 1 == grid.cell_count());  // a binary tree above the cut
        }
    }
}

TEST_CASE(
    "RayGrid: the image is bit-identical alone, with reordering and with AEPSA, at every SIMD "
    "back end, primary streams are untouched",
    "[stream][seeds]") {
    std::vector<Isa> isas = {Isa::scalar};
    for (const Isa isa : {Isa::avx2, Isa::avx512})
        if (isa_supported(isa)) isas.push_back(isa);
    for (const Scene& s : {test::box_scene(test::Variant::lights), sphere_wall()}) {
        const Bvh bvh(s);
        RenderSettings r = settings_for(s, 32, 24, 2, 16);
        const Run plain = run(s, bvh, r);
        CHECK(plain.result.stats.batch_queues == 0);
        for (OpKind k : {OpKind::raygrid_walk, OpKind::raygrid_enqueue})
            CHECK(plain.counts.kind_ops(k) == 0);
        for (const Isa isa : isas)
            for (uint32_t queue : {8u, 384u}) {
                RenderSettings g = r;
                g.isa = isa;
                g.batching = RayBatching::raygrid;
                g.batching_queue = queue;
                g.batching_cell_prims = 8;  // many cells in a small scene
                const Run batched = run(s, bvh, g);
                g.reorder = RayReorder::hit_point;
                const Run with_reorder = run(s, bvh, g);
                g.primary_entry = PrimaryEntry::aepsa;
                const Run all_three = run(s, bvh, g);
                g.reorder = RayReorder::none;
                const Run with_aepsa = run(s, bvh, g);
                INFO("scene " << s.name << " isa " << int(isa) << " queue " << queue);
                CHECK(same_bits(plain.result.image, batched.result.image));
                CHECK(same_bits(plain.result.image, with_reorder.result.image));
                CHECK(same_bits(plain.result.image, with_aepsa.result.image));
                CHECK(same_bits(plain.result.image, all_three.result.image));
                CHECK(batched.result.stats.rays() == plain.result.stats.rays());
                CHECK(batched.counts.rays() == plain.counts.rays());
                for (OpKind k : {OpKind::raygrid_walk, OpKind::raygrid_enqueue}) {
                    CHECK(batched.counts.kind_ops(k) > 0);
                    CHECK(batched.counts.kind_lanes(k, false) == 0);  // no primary ray batched
                }
                CHECK(batched.result.stats.batch_queues > 0);
                // Every queued ray was walked to its cell by one enqueue lane.
                CHECK(batched.result.stats.batch_queued_rays ==
                      batched.counts.kind_lanes(OpKind::raygrid_enqueue));
                if (queue == 8) CHECK(batched.result.stats.batch_full_queues > 0);
                // Primary rays are traced as before, op for op.
                CHECK(batched.counts.kind_lanes(OpKind::box_test, false) ==
                      plain.counts.kind_lanes(OpKind::box_test, false));
                CHECK(batched.counts.bounce(0).box_ops == plain.counts.bounce(0).box_ops);
            }
    }
}

TEST_CASE("RayGrid: a ray that hits in its first cell tests no box of a later cell",
          "[stream][seeds]") {
    // The sphere wall: secondary rays leave a sphere and mostly hit a neighbour or nothing.
    // Cells walked front to back stop a ray at its hit, so the secondary box-test lanes can
    // only fall, and the walk's bookkeeping is the price.
    const Scene s = sphere_wall();
    const Bvh bvh(s);
    RenderSettings r = settings_for(s, 32, 32, 1, 32);
    const Run plain = run(s, bvh, r);
    r.batching = RayBatching::raygrid;
    r.batching_cell_prims = 4;
    const Run batched = run(s, bvh, r);
    CHECK(same_bits(plain.result.image, batched.result.image));
    CHECK(batched.counts.kind_lanes(OpKind::box_test, true) <
          plain.counts.kind_lanes(OpKind::box_test, true));
    CHECK(batched.counts.kind_lanes(OpKind::raygrid_walk, true) > 0);
}

TEST_CASE("Workload shape: RayGrid units exist only when the workload batches", "[stream][seeds]") {
    WorkloadShape shape;
    shape.features = test::box_scene(test::Variant::lights).features();
    for (OpKind k : {OpKind::raygrid_walk, OpKind::raygrid_enqueue})
        CHECK_FALSE(shape.needed_kinds()[size_t(k)]);
    shape.batching_raygrid = true;
    for (OpKind k : {OpKind::raygrid_walk, OpKind::raygrid_enqueue})
        CHECK(shape.needed_kinds()[size_t(k)]);
    CHECK_FALSE(shape.needed_kinds()[size_t(OpKind::reorder_key)]);
}

TEST_CASE("RayGrid: its trace is the same on any thread count and reads back from a file",
          "[stream][seeds]") {
    const Scene s = test::box_scene(test::Variant::lights);
    const Bvh bvh(s);
    RenderSettings r = settings_for(s, 24, 16, 2, 8);
    r.batching = RayBatching::raygrid;
    r.batching_queue = 8;
    r.batching_cell_prims = 4;
    const std::string base = (std::filesystem::temp_directory_path() /
                              ("sfx_raygrid_trace_" + std::to_string(::getpid())))
                                 .string();
    const std::string p1 = base + "_1.trc", p2 = base + "_2.trc";
    r.threads = 1;
    CountingSink direct({8});
    render_stream(s, bvh, r, &direct);
    {
        TraceFileWriter w(p1);
        render_stream(s, bvh, r, &w);
    }
    r.threads = 2;
    {
        TraceFileWriter w(p2);
        render_stream(s, bvh, r, &w);
    }
    auto bytes = [](const std::string& p) {
        std::ifstream in(p, std::ios::binary);
        return std::string(std::istreambuf_iterator<char>(in), {});
    };
    CHECK(bytes(p1) == bytes(p2));
    CountingSink replayed({8});
    read_trace_file(p1, replayed);
    for (OpKind k : {OpKind::raygrid_walk, OpKind::raygrid_enqueue, OpKind::box_test}) {
        CHECK(replayed.kind_ops(k) == direct.kind_ops(k));
        CHECK(replayed.kind_lanes(k) == direct.kind_lanes(k));
    }
    CHECK(direct.kind_ops(OpKind::raygrid_walk) > 0);
    CHECK(replayed.rays() == direct.rays());
    std::filesystem::remove(p1);
    std::filesystem::remove(p2);
}
