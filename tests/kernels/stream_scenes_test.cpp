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
#include "tests/kernels/count_checks.h"
#include "workloads/scene_loader.h"

using namespace sfx;

namespace {
// 32 x 24, 2 spp, one thread: small enough for every scene and back end.
RenderSettings small_frame(const Scene& scene) {
    RenderSettings settings;
    settings.width = 32;
    settings.height = 24;
    settings.spp = 2;
    settings.max_depth = scene.max_depth;
    settings.threads = 1;
    return settings;
}
}  // namespace

TEST_CASE("Every shipped scene: stream image equals the reference image bit for bit",
          "[stream][scenes]") {
    for (const std::string& name : builtin_scene_names()) {
        const Scene scene = load_scene(name);
        const Bvh bvh(scene);
        RenderSettings settings = small_frame(scene);
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
        RenderSettings settings = small_frame(scene);
        settings.tile = 32;
        for (const Isa isa : supported_isas()) {
            INFO(name << " back end " << isa_name(isa));
            settings.isa = isa;
            CountingSink counts(widths);
            FullTraceCountingSink full(widths);
            REQUIRE(counts.counts_only());
            render_stream(scene, bvh, settings, &counts);
            render_stream(scene, bvh, settings, &full);
            test::check_same_counts(counts, full);
        }
    }
}
