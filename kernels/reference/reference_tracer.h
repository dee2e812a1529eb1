#pragma once
// The reference tracer: depth-first, one ray at a time, one path after another.
// It is the ground truth the stream tracer must match bit for bit.

#include "kernels/bvh.h"
#include "kernels/path.h"
#include "kernels/render.h"

namespace sfx {

// Traces one path to its end and returns its radiance (NaN/Inf included: callers decide).
Vec3 trace_reference_path(const Scene& scene, const Bvh& bvh, const RenderSettings& settings,
                          uint32_t pixel, uint32_t sample, RenderStats& stats);

RenderResult render_reference(const Scene& scene, const Bvh& bvh, const RenderSettings& settings);

// Zeroes a non-finite path radiance and counts it; shared by every tracer's film.
inline Vec3 sanitize_radiance(const Vec3& l, RenderStats& stats) {
    if (is_finite(l)) return l;
    ++stats.nonfinite_paths;
    return Vec3(0.f);
}

}  // namespace sfx
