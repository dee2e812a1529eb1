// sfx_bench_stream: on the same rays, one thread each, prints closest-hit throughput of
//   the reference traversal (Bvh::intersect, one ray at a time),
//   the stream traversal (stream_intersect, 64x64-ray streams) with the trace off and with a
//   counting sink, and Embree 3 rtcIntersect1 (robust scene, via EmbreeScene),
// for primary rays and diffuse-bounce rays, with ratios; then whole-frame path tracing,
// reference against stream (trace off / counting). Not a test: speeds vary by machine.
// Times are thread CPU seconds, median of N (default 5), so other processes on the machine matter
// less.
//
// Usage: sfx_bench_stream [SCENE] [--res WxH] [--repeat N] [--isa X]    (default: conference
// 512x512)

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <cstring>
#include <ctime>
#include <functional>
#include <string>

#include "kernels/bvh.h"
#include "kernels/camera.h"
#include "kernels/embree/embree_check.h"
#include "kernels/reference/reference_tracer.h"
#include "kernels/stream/stream_tracer.h"
#include "workloads/scene_loader.h"

using namespace sfx;

namespace {

// CPU seconds of this thread: on a shared machine, wall time measures the neighbours too.
double thread_seconds() {
    timespec ts;
    clock_gettime(CLOCK_THREAD_CPUTIME_ID, &ts);
    return double(ts.tv_sec) + 1e-9 * double(ts.tv_nsec);
}

// Median of `repeat` runs, in thread CPU seconds (every run here stays on the calling thread).
double median_seconds(int repeat, const std::function<void()>& run) {
    std::vector<double> times;
    for (int i = 0; i < repeat; ++i) {
        const double t0 = thread_seconds();
        run();
        times.push_back(thread_seconds() - t0);
    }
    std::sort(times.begin(), times.end());
    return times[times.size() / 2];
}

// Camera rays in tile order (64 x 64 tiles, one sample), so a 4096-ray stream is one tile.
std::vector<Ray> primary_rays(const Scene& scene, uint32_t w, uint32_t h) {
    const CameraFrame camera(scene.camera, w, h);
    std::vector<Ray> rays;
    for (const TileRect& t : make_tiles(w, h, 64))
        for (uint32_t y = t.y0; y < t.y1; ++y)
            for (uint32_t x = t.x0; x < t.x1; ++x)
                rays.push_back(camera.generate({0, y * w + x, 0}));
    return rays;
}

// One cosine-weighted bounce from each primary hit (what a Lambertian indirect step makes),
// in the same tile order; rays Embree would refuse are left out.
std::vector<Ray> diffuse_rays(const Scene& scene, const Bvh& bvh, const std::vector<Ray>& primary) {
    std::vector<Ray> rays;
    for (uint32_t i = 0; i < primary.size(); ++i) {
        const Hit hit = bvh.intersect(primary[i]);
        if (!hit.valid()) continue;
        const SurfaceHit s = surface_at(scene, primary[i], hit);
        Ray r;
        r.org = offset_ray_origin(s.position, s.normal);
        r.dir = to_world(sample_cosine_hemisphere(random_float(5, i, 0, 1, RngDim::direction_u),
                                                  random_float(5, i, 0, 1, RngDim::direction_v)),
                         s.normal);
        if (EmbreeScene::accepts(r)) rays.push_back(r);
    }
    return rays;
}

void report(const char* name, size_t rays, double seconds, double embree_rate) {
    const double rate = double(rays) / seconds;
    std::printf("  %-34s %8.2f Mrays/s", name, rate * 1e-6);
    if (embree_rate > 0) std::printf("   %.2fx Embree", rate / embree_rate);
    std::printf("\n");
}

}  // namespace

int main(int argc, char** argv) {
    std::string scene_name = "conference";
    uint32_t w = 512, h = 512;
    int repeat = 5;
    Isa only = Isa::automatic;
    std::string part;  // empty: every part
    for (int i = 1; i < argc; ++i) {
        const std::string a = argv[i];
        if (a == "--res" && i + 1 < argc) {
            if (std::sscanf(argv[++i], "%ux%u", &w, &h) != 2) return 2;
        } else if (a == "--isa" && i + 1 < argc) {
            only = parse_isa(argv[++i]);
        } else if (a == "--only" && i + 1 < argc) {
            part = argv[++i];
            if (part != "primary" && part != "diffuse" && part != "frames") {
                std::fprintf(stderr, "sfx_bench_stream: --only takes primary, diffuse or frames\n");
                return 2;
            }
        } else if (a == "--repeat" && i + 1 < argc) {
            repeat = std::max(1, std::atoi(argv[++i]));
        } else if (a == "-h" || a == "--help") {
            std::printf(
                "usage: sfx_bench_stream [SCENE] [--res WxH] [--repeat N] [--isa "
                "auto|avx512|avx2|scalar] [--only primary|diffuse|frames]\n");
            return 0;
        } else {
            scene_name = a;
        }
    }
    const Scene scene = load_scene(scene_name);
    const Bvh bvh(scene);
    const EmbreeScene embree(scene);
    std::printf("scene %s: %u primitives; %ux%u rays per set; median of %d; one thread\n",
                scene.name.c_str(), scene.primitive_count(), w, h, repeat);

    // Every back end the CPU has, widest last (`--isa X` measures one only).
    std::vector<Isa> isas = supported_isas();
    if (only != Isa::automatic) isas = {resolve_isa(only)};
    std::printf("stream back ends:");
    for (const Isa isa : isas) std::printf(" %s (%u lanes)", isa_name(isa), isa_width(isa));
    std::printf("; auto would pick %s\n", isa_name(best_isa()));

    const std::vector<Ray> primary = primary_rays(scene, w, h);
    const std::vector<Ray> diffuse = diffuse_rays(scene, bvh, primary);
    for (const auto& [label, rays] :
         {std::pair<const char*, const std::vector<Ray>*>{"primary rays", &primary},
          {"diffuse-bounce rays", &diffuse}}) {
        if (!part.empty() && std::strncmp(label, part.c_str(), part.size()) != 0) continue;
        std::printf("\n%s (%zu)\n", label, rays->size());
        std::vector<Hit> ref(rays->size()), st, em(rays->size());
        const double t_embree = median_seconds(repeat, [&] {
            for (size_t i = 0; i < rays->size(); ++i) em[i] = embree.intersect((*rays)[i]);
        });
        const double t_ref = median_seconds(repeat, [&] {
            for (size_t i = 0; i < rays->size(); ++i) ref[i] = bvh.intersect((*rays)[i]);
        });
        // The stream traversal with each back end the CPU has, side by side on the same rays.
        std::vector<std::pair<Isa, double>> t_stream, t_counting;
        size_t differ = 0;
        CountingSink counts({8, 16});
        for (const Isa isa : isas) {
            t_stream.push_back({isa, median_seconds(repeat, [&] {
                                    stream_intersect(bvh, *rays, st, nullptr, isa);
                                })});
            for (size_t i = 0; i < rays->size(); ++i)
                differ += std::memcmp(&ref[i], &st[i], sizeof(Hit)) != 0;
            CountingSink c({8, 16});
            t_counting.push_back(
                {isa, median_seconds(repeat, [&] { stream_intersect(bvh, *rays, st, &c, isa); })});
            if (isa == isas.back()) counts = c;
        }
        size_t embree_differ = 0;
        for (size_t i = 0; i < rays->size(); ++i) embree_differ += ref[i].prim != em[i].prim;
        const double embree_rate = double(rays->size()) / t_embree;
        report("Embree rtcIntersect1", rays->size(), t_embree, embree_rate);
        report("reference (Bvh::intersect)", rays->size(), t_ref, embree_rate);
        for (size_t k = 0; k < isas.size(); ++k) {
            const std::string name = std::string("stream ") + isa_name(isas[k]);
            report((name + ", trace off").c_str(), rays->size(), t_stream[k].second, embree_rate);
            report((name + ", counting sink").c_str(), rays->size(), t_counting[k].second,
                   embree_rate);
        }
        std::printf(
            "  stream hits differing from reference (all back ends): %zu; "
            "primitive differs from Embree's: %zu\n",
            differ, embree_differ);
        TraversalCounts reference;  // Bvh::intersect's own tests, counted by its policy
        for (const Ray& r : *rays) bvh.intersect(r, reference);
        const double n = double(rays->size()), runs = double(repeat);
        std::printf(
            "  tests per ray: reference %.1f box, %.1f primitive; stream %.1f box, %.1f "
            "primitive in ops of %.1f and %.1f rays on average\n",
            double(reference.boxes) / n, double(reference.primitives) / n,
            double(counts.kind_lanes(OpKind::box_test)) / runs / n,
            double(counts.kind_lanes(OpKind::triangle_test) +
                   counts.kind_lanes(OpKind::sphere_test)) /
                runs / n,
            counts.stage(false, OpStage::traversal).average_length(),
            counts.stage(false, OpStage::intersection).average_length());
    }

    if (!part.empty() && part != "frames") return 0;
    // Whole frames: path tracing with all generations, shading included.
    RenderSettings settings;
    settings.width = w / 2;
    settings.height = h / 2;
    settings.spp = 4;
    settings.max_depth = scene.max_depth;
    settings.tile = 64;
    settings.threads = 1;
    RenderResult ref_frame, st_frame;
    const double f_ref =
        median_seconds(repeat, [&] { ref_frame = render_reference(scene, bvh, settings); });
    const size_t n = ref_frame.stats.rays();
    std::printf("\npath tracing %ux%u x %u spp, tile 64 (%zu rays)\n", settings.width,
                settings.height, settings.spp, n);
    report("reference tracer", n, f_ref, 0);
    for (const Isa isa : isas) {
        settings.isa = isa;
        const double f_st =
            median_seconds(repeat, [&] { st_frame = render_stream(scene, bvh, settings); });
        CountingSink counts({8, 16});
        const double f_count =
            median_seconds(repeat, [&] { render_stream(scene, bvh, settings, &counts); });
        const bool same = std::memcmp(ref_frame.image.pixels.data(), st_frame.image.pixels.data(),
                                      ref_frame.image.pixels.size() * sizeof(Vec3)) == 0;
        const std::string name = std::string("stream ") + isa_name(isa);
        report((name + ", trace off").c_str(), n, f_st, 0);
        report((name + ", counting sink").c_str(), n, f_count, 0);
        std::printf("  %s: stream / reference %.2fx (trace off), %.2fx (counting); image %s\n",
                    isa_name(isa), f_ref / f_st, f_ref / f_count,
                    same ? "bit-identical to the reference" : "DIFFERS from the reference");
        // Where the time goes: one more frame with the stage clock (trace off).
        RenderSettings clocked = settings;
        clocked.stage_clock = true;
        const RenderStats split = render_stream(scene, bvh, clocked).stats;
        const double ticks =
            double(split.stage_tsc[0] + split.stage_tsc[1] + split.stage_tsc[2]) / 100.0;
        std::printf(
            "  %s stage clock, one frame: traversal %.0f %%, intersection %.0f %%, shading and "
            "the rest %.0f %%; %.0f TSC ticks per ray\n",
            isa_name(isa), double(split.stage_tsc[0]) / ticks, double(split.stage_tsc[1]) / ticks,
            double(split.stage_tsc[2]) / ticks, ticks * 100.0 / double(n));
    }
    return 0;
}
