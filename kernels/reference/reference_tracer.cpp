#include "kernels/reference/reference_tracer.h"

#include <mutex>

#include "kernels/camera.h"
#include "base/host_clock.h"

namespace sfx {

static Vec3 trace_path(const Scene& scene, const Bvh& bvh, const CameraFrame& camera,
                       const RenderSettings& settings, uint32_t pixel, uint32_t sample,
                       RenderStats& stats) {
    PathState p;
    p.key = {settings.seed, pixel, sample};
    Ray ray = camera.generate(p.key);
    ++stats.camera_rays;
    for (;;) {
        if (p.kind == RayKind::shadow) {
            finish_shadow(p, bvh.occluded(ray));
            break;
        }
        const Hit hit = bvh.intersect(ray);
        Ray next;
        if (!shade(p, scene, settings.max_depth, ray, hit, next)) break;
        ++(p.kind == RayKind::shadow ? stats.shadow_rays : stats.extension_rays);
        ray = next;
    }
    return p.radiance;
}

Vec3 trace_reference_path(const Scene& scene, const Bvh& bvh, const RenderSettings& settings,
                          uint32_t pixel, uint32_t sample, RenderStats& stats) {
    const CameraFrame camera(scene.camera, settings.width, settings.height);
    return trace_path(scene, bvh, camera, settings, pixel, sample, stats);
}

RenderResult render_reference(const Scene& scene, const Bvh& bvh, const RenderSettings& settings) {
    const auto start = HostClock::now();
    const CameraFrame camera(scene.camera, settings.width, settings.height);
    RenderResult result;
    result.image = Image(settings.width, settings.height);
    // Small tiles balance threads; the tiling never changes a pixel (each pixel is its own sum).
    const std::vector<TileRect> tiles = make_tiles(settings.width, settings.height, 16);
    std::mutex stats_mutex;
    parallel_for(uint32_t(tiles.size()), settings.threads, [&](uint32_t t) {
        RenderStats local;
        const TileRect& r = tiles[t];
        for (uint32_t y = r.y0; y < r.y1; ++y)
            for (uint32_t x = r.x0; x < r.x1; ++x) {
                const uint32_t pixel = y * settings.width + x;
                Vec3 sum(0.f);
                for (uint32_t s = 0; s < settings.spp; ++s)
                    sum += sanitize_radiance(
                        trace_path(scene, bvh, camera, settings, pixel, s, local), local);
                result.image.at(x, y) = sum / float(settings.spp);
            }
        std::lock_guard<std::mutex> lock(stats_mutex);
        result.stats += local;
    });
    result.stats.host_seconds = seconds_since(start);
    return result;
}

}  // namespace sfx
