// Every shipped scene: the stream tracer's image equals the reference's, bit for bit, for
// tiles 1, 8, 32, 64 and threads 1, 2 (small resolutions; `sfx validate` checks any size).

#include <catch2/catch.hpp>
#include <cstring>

#include "kernels/bvh.h"
#include "kernels/reference/reference_tracer.h"
#include "kernels/stream/stream_tracer.h"
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
