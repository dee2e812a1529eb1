#pragma once
// Entry points for primary-ray streams (AEPSA, seeds/004 Sec. 3, after MLRTA's ray proxy
// frustum): the tile's rays are bounded by one proxy, and the search finds the deepest BVH node
// whose subtree holds every leaf the proxy overlaps. Traversal of the tile's stream may start
// there: a ray can only hit a primitive in a leaf its own box test reaches, every such leaf is
// overlapped by the proxy, so no hit is lost and none changes (the image stays bit-identical).
//
// The proxy is a frustum of five planes around the tile's rays (MLRTA's ray proxy frustum): the
// tracer's camera has a thin lens, so the planes are fitted to the rays themselves rather than
// to a common apex (FrustumProxy::build). Its box test is conservative against the stream's
// float slab test by a margin (FrustumProxy::overlaps).

#include <cmath>
#include <cstdint>
#include <vector>

#include "kernels/bvh.h"

namespace sfx {

struct FrustumProxy {
    // Every point of every ray (t >= 0) satisfies n . x <= d.
    struct Plane {
        double n[3];
        double d;
    };
    Plane planes[5];
    uint32_t plane_count = 0;  // 0: the rays spread too wide for planes (overlaps everything)
    bool empty = true;         // no ray

    // Fits the planes to `count` rays, `ray(i)` giving the i-th RayPrecomp, in two passes (the
    // frustum_bounds op): the mean direction w, then each ray's slopes against a frame (u, v, w)
    // and its origin's coordinates in it. The side planes hold every direction's slopes; their
    // offsets and a back plane (-w) hold every origin.
    template <class Ray>
    void build(uint32_t count, Ray&& ray);
    // False only if no ray the proxy bounds can pass the slab test of `box`.
    bool overlaps(const Bounds3& box) const;

  private:
    void fit(const double w[3], uint32_t count, const RayPrecomp* const* rays);
};

struct EntryPoint {
    uint32_t node = 0;   // where traversal of the proxied rays starts
    uint32_t depth = 0;  // its depth (root 0)
};

// The two phases of AEPSA over a BVH. `test(node, overlapped)` is called for every frustum
// test in the order the search makes them (the tracer turns each into a frustum_test op).
// Phase 1: depth-first (left child first) from the root to the first overlapped leaf; a node
// both of whose children the frustum overlaps goes on the candidate queue (a node whose first
// subtree turned out to hold no overlapped leaf leaves it again). Phase 2: candidates top-down;
// the first whose untaken branch holds an overlapped leaf is the entry point; if none does,
// the leaf is. If the frustum overlaps no leaf, the entry is the root (its box test then
// culls the stream).
template <class Test>
EntryPoint find_entry_point(const Bvh& bvh, const FrustumProxy& frustum, Test&& test);

// ---- implementation ------------------------------------------------------------------------

template <class Ray>
void FrustumProxy::build(uint32_t count, Ray&& ray) {
    empty = count == 0;
    plane_count = 0;
    if (empty) return;
    std::vector<const RayPrecomp*> rays(count);
    double w[3] = {0.0, 0.0, 0.0};
    for (uint32_t i = 0; i < count; ++i) {
        rays[i] = &ray(i);
        const Vec3& d = rays[i]->dir;
        const double len = std::sqrt(double(d.x) * d.x + double(d.y) * d.y + double(d.z) * d.z);
        for (int a = 0; a < 3; ++a) w[a] += double(d[a]) / len;
    }
    fit(w, count, rays.data());
}

namespace entry_detail {

// Depth-first search below `node` (already overlapped) for an overlapped leaf; `path`
// receives (node, untaken child, depth) for nodes both of whose children overlap.
struct Candidate {
    uint32_t node, untaken, depth;
};

template <class Test>
bool descend(const BvhNodes& nodes, const FrustumProxy& f, uint32_t index, uint32_t depth,
             Test& test, std::vector<Candidate>* queue, uint32_t& leaf, uint32_t& leaf_depth) {
    const BvhNode& node = nodes[index];
    if (node.is_leaf()) {
        leaf = index;
        leaf_depth = depth;
        return true;
    }
    const uint32_t left = BvhNode::left(index), right = node.right();
    const bool l = f.overlaps(nodes[left].bounds);
    test(left, l);
    const bool r = f.overlaps(nodes[right].bounds);
    test(right, r);
    if (l && r) {
        if (queue) queue->push_back({index, right, depth});
        if (descend(nodes, f, left, depth + 1, test, queue, leaf, leaf_depth)) return true;
        if (queue) queue->pop_back();  // only the right branch can hold overlapped leaves
        return descend(nodes, f, right, depth + 1, test, queue, leaf, leaf_depth);
    }
    if (l) return descend(nodes, f, left, depth + 1, test, queue, leaf, leaf_depth);
    if (r) return descend(nodes, f, right, depth + 1, test, queue, leaf, leaf_depth);
    return false;
}

}  // namespace entry_detail

template <class Test>
EntryPoint find_entry_point(const Bvh& bvh, const FrustumProxy& frustum, Test&& test) {
    const BvhNodes& nodes = bvh.nodes();
    if (frustum.empty || nodes.empty()) return {};
    const bool root = frustum.overlaps(nodes[0].bounds);
    test(0u, root);
    if (!root) return {};
    std::vector<entry_detail::Candidate> queue;  // phase 1's candidates, top-down
    uint32_t leaf = 0, leaf_depth = 0;
    if (!entry_detail::descend(nodes, frustum, 0, 0, test, &queue, leaf, leaf_depth)) return {};
    // Phase 2: the untaken branch of each candidate, highest first.
    for (const entry_detail::Candidate& c : queue) {
        uint32_t other = 0, other_depth = 0;
        if (entry_detail::descend(nodes, frustum, c.untaken, c.depth + 1, test, nullptr, other,
                                  other_depth))
            return {c.node, c.depth};
    }
    return {leaf, leaf_depth};
}

}  // namespace sfx
