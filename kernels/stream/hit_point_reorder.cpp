#include "kernels/stream/hit_point_reorder.h"

#include <algorithm>
#include <cmath>

namespace sfx {

namespace {

// The bits of a 6-bit number spread to every third bit (a Z-curve index of one axis).
uint64_t spread6(uint32_t v) {
    uint64_t out = 0;
    for (int b = 0; b < 6; ++b) out |= uint64_t((v >> b) & 1u) << (3 * b);
    return out;
}

uint64_t morton6(uint32_t x, uint32_t y, uint32_t z) {
    return spread6(x) | (spread6(y) << 1) | (spread6(z) << 2);
}

}  // namespace

HitPointReorder::HitPointReorder(const Bvh& bvh, uint32_t ppm) {
    const BvhNodes& nodes = bvh.nodes();
    m_proxy.assign(nodes.size(), 0);
    if (nodes.empty()) return;
    m_bounds = nodes[0].bounds;
    // Primitives under each node; children come after their parent (depth-first build).
    std::vector<uint64_t> prims(nodes.size(), 0);
    for (size_t i = nodes.size(); i-- > 0;) {
        const BvhNode& n = nodes[i];
        prims[i] = n.is_leaf() ? n.count : prims[BvhNode::left(uint32_t(i))] + prims[n.right()];
    }
    // A proxy stands for at most 1e6 / ppm primitives: the highest such nodes (or leaves).
    const double per_proxy = std::max(1.0, 1e6 / double(std::max(1u, ppm)));
    std::vector<uint32_t> stack = {0};
    while (!stack.empty()) {
        const uint32_t i = stack.back();
        stack.pop_back();
        const BvhNode& n = nodes[i];
        if (n.is_leaf() || double(prims[i]) <= per_proxy) {
            m_proxy[i] = 1;
            ++m_proxy_count;
            continue;
        }
        stack.push_back(n.right());
        stack.push_back(BvhNode::left(i));
    }
}

uint64_t HitPointReorder::key(const Vec3& p) const {
    // 2^12 cells per axis in all: 2^6 high-level cells, each split in 2^6 low-level ones.
    uint32_t q[3];
    for (int a = 0; a < 3; ++a) {
        const float extent = m_bounds.hi[a] - m_bounds.lo[a];
        const float f = extent > 0.f ? (p[a] - m_bounds.lo[a]) / extent : 0.f;
        const float cell = std::floor(f * 4096.f);
        q[a] = cell > 0.f ? uint32_t(std::min(cell, 4095.f)) : 0u;  // also NaN -> 0
    }
    const uint64_t high = morton6(q[0] >> 6, q[1] >> 6, q[2] >> 6);
    const uint64_t low = morton6(q[0] & 63u, q[1] & 63u, q[2] & 63u);
    return (high << 18) | low;
}

float HitPointReorder::scene_exit(const RayPrecomp& r, float t_max) const {
    float t0 = 0.f, t1 = t_max;
    for (int a = 0; a < 3; ++a) {
        if (r.dir[a] == 0.f) {
            if (r.org[a] < m_bounds.lo[a] || r.org[a] > m_bounds.hi[a]) return INFINITY;
            continue;
        }
        float t_near = (m_bounds.lo[a] - r.org[a]) * r.inv_dir[a];
        float t_far = (m_bounds.hi[a] - r.org[a]) * r.inv_dir[a];
        if (t_near > t_far) std::swap(t_near, t_far);
        t0 = std::max(t0, t_near);
        t1 = std::min(t1, t_far);
    }
    return t0 <= t1 && std::isfinite(t1) ? t1 : INFINITY;
}

}  // namespace sfx
