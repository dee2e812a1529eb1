#pragma once
// What every tracer takes and gives: render settings, the film, and per-render statistics.

#include <cstdint>
#include <functional>
#include <string>
#include <vector>

#include "base/vec.h"
#include "kernels/simd/isa.h"
#include "kernels/trace.h"

namespace sfx {

// The frame (resolution, samples, depth, tile, seed, the seed papers' options) is a
// TraceFrame, declared once in kernels/trace.h: the trace header carries the same fields.
// What is added here changes neither the image nor the trace.
struct RenderSettings : TraceFrame {
    uint32_t threads = 0;      // 0: all hardware threads
    Isa isa = Isa::automatic;  // the stream filters' host back end; never changes a bit
    // The stream tracer reads the time-stamp counter at stage boundaries (RenderStats::
    // stage_tsc); off by default (it costs a few cycles per leaf visited); never changes a bit.
    bool stage_clock = false;
    // The stream tracer reads the time-stamp counter at the end of each generation of a pass
    // and of the pass (RenderStats::part_tsc); a few reads a pass; never changes a bit.
    bool part_clock = false;
};

// The workload's k-th other frame (k >= 1): the same scene, image, tiles and settings, other
// random numbers (seed + k), as a progressive renderer's next frames. A CPU core's branch
// predictor learns a frame's random outcomes from a render of that very frame: on an AMD Zen 4
// VM (AVX2, 64 x 64, 2026-12-05), furnace's Lambertian lobe choice took 133 K TSC ticks right
// after a render of its own frame and 252 K after one of another seed (cornell's 99-125 and
// 164; its frame 2.5 % faster), and more of it the longer the tile's streams. So a frame timed
// warm follows other frames (sampling's warm frames, the silicon check's renders).
inline RenderSettings other_frame(RenderSettings settings, uint64_t k) {
    settings.seed += k;
    return settings;
}

// One float RGB value per pixel. Each pixel is the mean of its samples, summed in sample
// order, so neither thread count nor tile order changes a bit.
struct Image {
    uint32_t width = 0, height = 0;
    std::vector<Vec3> pixels;

    Image() = default;
    Image(uint32_t w, uint32_t h) : width(w), height(h), pixels(size_t(w) * h) {}
    Vec3& at(uint32_t x, uint32_t y) { return pixels[size_t(y) * width + x]; }
    const Vec3& at(uint32_t x, uint32_t y) const { return pixels[size_t(y) * width + x]; }
    Vec3 mean() const;
};

void write_pfm(const Image& image, const std::string& path);
void write_png(const Image& image, const std::string& path);  // sRGB, clamped
Image read_pfm(const std::string& path);

struct RenderStats {
    uint64_t camera_rays = 0;
    uint64_t extension_rays = 0;
    uint64_t shadow_rays = 0;
    uint64_t nonfinite_paths = 0;  // paths whose radiance was NaN/Inf: zeroed, counted
    // Primary entry search (PrimaryEntry::aepsa): frusta searched and the sum of the depths
    // (root = 0) of the nodes their rays entered at.
    uint64_t entry_searches = 0;
    uint64_t entry_depth_sum = 0;
    // RayGrid batching: queues traced, how many of them were full, and the rays they held.
    uint64_t batch_queues = 0;
    uint64_t batch_full_queues = 0;
    uint64_t batch_queued_rays = 0;
    double host_seconds = 0.0;
    // With RenderSettings::stage_clock (stream tracer): TSC ticks per stage, [traversal,
    // intersection, shading] as kernels/trace.h's OpStage; shading is the rest of each pass
    // (camera, ray set-up, the shading filter stack).
    uint64_t stage_tsc[3] = {0, 0, 0};
    // Of stage_tsc[0] (stream tracer, stage clock): the ticks of the one-ray loop ([0]) and
    // of the few-ray loop ([1]) run from the stream loop (kernels/stream), their leaves' not
    // included: where a traversal's short streams go (kernels/trace.h).
    uint64_t short_loop_tsc[2] = {0, 0};
    // Of stage_tsc[1]: the ticks of the leaves the one-ray ([0]) and few-ray ([1]) loops reach
    // (the stream loop's leaves are the rest).
    uint64_t short_loop_leaf_tsc[2] = {0, 0};
    // Of stage_tsc[2] (stream tracer, stage clock): the ticks of each shading op kind as the
    // timing models price it (camera: the camera loop; emission_filter: with the hits'
    // surfaces, compute_surfaces; material_filter: the sort by material), of the ray set-up
    // (load_rays), which they price in the ops that made the rays, and of the rest (the
    // reordering, the sums into the image): laps of one clock, so that the three make the stage.
    uint64_t shading_op_tsc[k_op_kind_count] = {};
    uint64_t ray_setup_tsc = 0;
    uint64_t shading_rest_tsc = 0;
    // With RenderSettings::part_clock (stream tracer): each part's TSC ticks, a part being a
    // generation of a pass (the first with its camera rays) or a pass's end (its sums), in the
    // order they ran; with one thread that is the same order, and the same work, in every
    // render of a frame (sfx calibrate --check takes each part's fastest over its renders).
    std::vector<uint64_t> part_tsc;
    // The TSC when each part started: where in the render it ran, for the contention monitor's
    // probes around it (base/core_contention.h, clean_spans).
    std::vector<uint64_t> part_start_tsc;

    uint64_t rays() const { return camera_rays + extension_rays + shadow_rays; }
    RenderStats& operator+=(const RenderStats& o);
};

struct RenderResult {
    Image image;
    RenderStats stats;
};

// Tiles of the image in row-major order, each tile_size^2 pixels (clipped at the border).
struct TileRect {
    uint32_t x0, y0, x1, y1;
};
std::vector<TileRect> make_tiles(uint32_t width, uint32_t height, uint32_t tile_size);

// Runs job(i) for i in [0, count) on `threads` threads (0: hardware concurrency), each index
// exactly once; which thread runs which index never matters to callers.
void parallel_for(uint32_t count, uint32_t threads, const std::function<void(uint32_t)>& job);
// The most threads a --threads flag accepts: far above any host sfx runs on, and low enough
// that a mistyped value is an error rather than a process that tries to start a million threads.
constexpr uint32_t k_max_threads = 1024;

}  // namespace sfx
