#pragma once
// The stream-filtering path tracer (Gribble & Ramani 2008, Sections 3-4): breadth-first ray
// streams through BVH traversal (Fig. 3), intersection filters and the shading filter stack
// (Fig. 4), one tile pass (T x T primary rays, one sample per pixel) at a time.
//
// The box and triangle filters run at the host's SIMD width through the back end chosen by
// RenderSettings::isa (kernels/stream/stream_kernels.h); the image and the trace never
// depend on it.
//
// It calls the same per-ray functions as the reference tracer in the same per-path order, so
// its image is bit-identical to the reference's: camera ray, RayPrecomp, intersect_box,
// Bvh::intersect_primitive (ties to the lower id), surface_at and the path steps of path.h.
// Every stream operation goes to a TraceSink (kernels/trace.h) when one is given.

#include <cstdint>
#include <memory>
#include <vector>

#include "kernels/bvh.h"
#include "kernels/path.h"
#include "kernels/render.h"
#include "kernels/trace.h"

namespace sfx {

// Sees every traced ray of a pass with its result (tests compare hit records through it).
class RayObserver {
  public:
    virtual ~RayObserver() = default;
    virtual void ray(const PathState& path, const Ray& ray, const Hit& hit, bool occluded) = 0;
};

class StreamTracer {
  public:
    StreamTracer(const Scene& scene, const Bvh& bvh, const RenderSettings& settings);
    ~StreamTracer();
    StreamTracer(const StreamTracer&) = delete;
    StreamTracer& operator=(const StreamTracer&) = delete;

    // One tile pass: sample `sample` of every pixel in `rect`, traced until no ray is left.
    // Adds each path's sanitized radiance to sums[slot], slot = row-major pixel in the tile.
    // `sink` (may be null: zero cost) receives begin_pass, every op, end_pass.
    void trace_pass(const TileRect& rect, uint32_t tile_index, uint32_t sample, Vec3* sums,
                    RenderStats& stats, TraceSink* sink, RayObserver* observer = nullptr);

  private:
    struct Impl;
    std::unique_ptr<Impl> m_impl;
};

// Renders the whole image with the stream tracer. Threads take whole tiles; each tile's
// passes run in sample order, so neither thread count nor tile order changes a bit. With a
// sink, the trace arrives in tile order, then sample order, whatever the thread count, and
// at most one pass per thread is held in memory. A CountingSink is the exception: counts are
// sums, so each tile counts on its own and the counts are added (same totals, no ordering).
RenderResult render_stream(const Scene& scene, const Bvh& bvh, const RenderSettings& settings,
                           TraceSink* sink = nullptr);

// A tracer's ray buffers outlive it: the next tracer takes them, sized and in the caches (a
// render's are the render before's, as a machine's ray buffers stay from frame to frame). This
// frees the ones kept, so that the next render allocates its own wherever the heap places them
// then (the silicon check varies that placement from round to round).
void release_kept_ray_buffers();

// Closest hits of an arbitrary ray list traced as one stream (Fig. 3 traversal). Used by the
// benchmark and the hit-record checks. hits[i] is what Bvh::intersect(rays[i]) returns.
// `isa`: the back end of the filters (the hits and the trace are the same for every one).
void stream_intersect(const Bvh& bvh, const std::vector<Ray>& rays, std::vector<Hit>& hits,
                      TraceSink* sink = nullptr, Isa isa = Isa::automatic);

}  // namespace sfx
