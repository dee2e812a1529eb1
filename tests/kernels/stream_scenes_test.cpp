// Every shipped scene: the stream tracer's image equals the reference's, bit for bit, for
// tiles 1, 8, 32, 64 and threads 1, 2 (small resolutions; `sfx validate` checks any size).

#include <catch2/catch.hpp>
#include <cstring>
#include <string>
#include <vector>

#include "kernels/bvh.h"
#include "kernels/reference/reference_tracer.h"
#include "kernels/simd/isa.h"
#include "kernels/stream/stream_tracer.h"
#include "kernels/trace.h"
#include "workloads/scene_loader.h"

using namespace sfx;

TEST_CASE("Every shipped scene: stream image equals the reference image bit for bit",
          "[stream][scenes]") {
    for (const std::string& name : builtin_scene_names()) {
        const Scene scene = load_scene(name);
        const Bvh bvh(scene);
        RenderSettings settings;
        settings.width = 32;
        settings.height = 24;
        settings.spp = 2;
        settings.max_depth = scene.max_depth;
        settings.threads = 1;
        const RenderResult ref = render_reference(scene, bvh, settings);
        for (uint32_t tile : {1u, 8u, 32u, 64u})
            for (uint32_t threads : {1u, 2u}) {
                settings.tile = tile;
                settings.threads = threads;
                const RenderResult st = render_stream(scene, bvh, settings);
                size_t differ = 0;
                for (size_t i = 0; i < ref.image.pixels.size(); ++i)
                    differ += std::memcmp(&ref.image.pixels[i], &st.image.pixels[i],
                                          sizeof(Vec3)) != 0;
                INFO(name << " tile " << tile << " threads " << threads);
                CHECK(differ == 0);
                CHECK(st.stats.rays() == ref.stats.rays());
            }
    }
}

namespace {
// A counting sink that takes the tracer's full-trace path: every op with its slots and pass
// flags, one call each, through the stream loop for every stream length.
struct FullTraceCountingSink : CountingSink {
    using CountingSink::CountingSink;
    bool counts_only() const override { return false; }
};
}  // namespace

TEST_CASE("Every shipped scene: the counts-only traversal counts what the full trace counts",
          "[stream][scenes]") {
    // The counts-only path tallies ops by length and walks streams of up to four rays as lane
    // masks (traverse_few); the full trace walks every stream as a partitioned list of ids.
    const std::vector<uint32_t> widths{4, 8, 12, 16};
    for (const std::string& name : builtin_scene_names()) {
        const Scene scene = load_scene(name);
        const Bvh bvh(scene);
        RenderSettings settings;
        settings.width = 32;
        settings.height = 24;
        settings.spp = 2;
        settings.max_depth = scene.max_depth;
        settings.threads = 1;
        settings.tile = 32;
        for (const Isa isa : supported_isas()) {
            INFO(name << " back end " << isa_name(isa));
            settings.isa = isa;
            CountingSink counts(widths);
            FullTraceCountingSink full(widths);
            REQUIRE(counts.counts_only());
            render_stream(scene, bvh, settings, &counts);
            render_stream(scene, bvh, settings, &full);
            CHECK(counts.rays() == full.rays());
            for (const bool secondary : {false, true})
                for (uint32_t st = 0; st < k_op_stage_count; ++st) {
                    const auto& a = counts.stage(secondary, OpStage(st));
                    const auto& b = full.stage(secondary, OpStage(st));
                    CHECK(a.ops == b.ops);
                    CHECK(a.lanes == b.lanes);
                    CHECK(a.passed == b.passed);
                    CHECK(a.groups == b.groups);
                    CHECK(a.histogram == b.histogram);
                }
            for (uint32_t k = 0; k < k_op_kind_count; ++k) {
                CHECK(counts.kind_ops(OpKind(k)) == full.kind_ops(OpKind(k)));
                CHECK(counts.kind_lanes(OpKind(k)) == full.kind_lanes(OpKind(k)));
            }
            for (uint32_t g = 0; g < CountingSink::k_bounce_slots; ++g) {
                CHECK(counts.bounce(g).rays == full.bounce(g).rays);
                CHECK(counts.bounce(g).box_lanes == full.bounce(g).box_lanes);
                CHECK(counts.bounce(g).prim_lanes == full.bounce(g).prim_lanes);
            }
        }
    }
}
