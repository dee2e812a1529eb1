#pragma once
// Hit-point reordering (Moon et al., seeds/001 Sec. 4): before a generation of secondary rays
// is traced, each ray gets an approximate hit point on simplified geometry, a key on a Z-curve
// over a two-level grid of the scene's bounds, and the stream is sorted by key. Hits do not
// depend on the order of a stream, so the image stays bit-identical.
//
// The simplified geometry here is a cut of the scene's own BVH: the highest nodes whose
// subtree holds at most 1/fraction primitives stand for their primitives (their boxes are the
// proxies), so about `fraction` of the primitive count remain, the paper's measure. The paper
// simplifies the mesh by quadric edge collapse instead; a box is a coarser proxy than a
// simplified triangle patch. A proxy box that contains the ray's origin is not a hit (the ray
// is leaving a surface that box stands for). A ray that hits no proxy takes the point where it
// leaves the scene's box (the paper's "virtual hit point"); one that misses the scene sorts
// last.

#include <cstdint>
#include <vector>

#include "kernels/bvh.h"

namespace sfx {

class HitPointReorder {
  public:
    // `ppm`: the simplified geometry's size in parts per million of the primitives.
    HitPointReorder(const Bvh& bvh, uint32_t ppm);

    // The node ends the simplified hierarchy (its box is a proxy).
    bool is_proxy(uint32_t node) const { return m_proxy[node] != 0; }
    uint64_t proxies() const { return m_proxy_count; }

    // The two-level grid key of a point (c = 6, the paper's: 2^6 cells per axis at each level,
    // K = K_high * 2^18 + K_low, each a Z-curve index of its level's cell).
    uint64_t key(const Vec3& p) const;
    static constexpr uint64_t k_no_key = ~uint64_t(0);  // a ray that misses the scene

    // The virtual hit point's distance: where the ray leaves the scene's box (INFINITY: misses).
    float scene_exit(const RayPrecomp& r, float t_max) const;

  private:
    Bounds3 m_bounds;
    std::vector<uint8_t> m_proxy;
    uint64_t m_proxy_count = 0;
};

}  // namespace sfx
