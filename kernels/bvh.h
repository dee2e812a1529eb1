#pragma once
// Binned-SAH bounding volume hierarchy over a scene's primitives (triangles and spheres).
// The build is single-threaded and deterministic: the same scene gives the same tree, byte
// for byte, so traces and images never depend on the machine.

#include <cstdint>
#include <vector>

#include "base/huge_pages.h"
#include "kernels/intersect.h"
#include "kernels/ray.h"
#include "kernels/trace.h"
#include "workloads/scene.h"

namespace sfx {

// 32 bytes, two to a cache line: the children of a node are visited together, and the left
// child is stored right after its parent (the build is depth first), so only the right
// child's index is kept.
struct alignas(32) BvhNode {
    Bounds3 bounds;
    uint32_t first = 0;  // leaf: first index into Bvh::prim_ids; interior: right child index
    uint16_t count = 0;  // leaf: primitive count (> 0); interior: 0
    uint8_t axis = 0;    // interior: split axis, for front-to-back order

    bool is_leaf() const { return count > 0; }
    static uint32_t left(uint32_t index) { return left_child_index(index); }
    uint32_t right() const { return first; }
};
static_assert(sizeof(BvhNode) == 32, "BvhNode must stay 32 bytes");

// The tree's arrays: read at random by every traversal, so in huge pages where the kernel
// gives them (base/huge_pages.h).
using BvhNodes = std::vector<BvhNode, HugePageAllocator<BvhNode>>;
using LeafPrimitives = std::vector<LeafPrimitive, HugePageAllocator<LeafPrimitive>>;

struct BvhBuildOptions {
    uint32_t max_leaf_size = 4;
    uint32_t bins = 16;
    float traversal_cost = 1.f;     // SAH cost of one box test, relative to one primitive test
    float intersection_cost = 1.f;
};

struct BvhStats {
    uint64_t nodes = 0;
    uint64_t leaves = 0;
    uint32_t max_depth = 0;
    double average_leaf_depth = 0.0;
    double average_leaf_size = 0.0;
    uint32_t max_leaf_size = 4;
    double sah_cost = 0.0;
    uint64_t bytes = 0;
};

// Counting policies of Bvh::intersect: none (compiles away), or box and primitive tests.
struct NoTraversalCounts {
    void box() {}
    void primitive() {}
};
struct TraversalCounts {
    uint64_t boxes = 0, primitives = 0;
    void box() { ++boxes; }
    void primitive() { ++primitives; }
};

class Bvh {
public:
    static constexpr uint32_t k_sah_depth_limit = 64;
    static constexpr uint32_t k_max_depth = k_sah_depth_limit + 33;  // + log2(2^32) median levels

    Bvh() = default;
    Bvh(const Scene& scene, const BvhBuildOptions& options = {});

    const BvhNodes& nodes() const { return m_nodes; }
    const std::vector<uint32_t>& prim_ids() const { return m_prim_ids; }
    // prim_ids' primitives with their vertices, in the same order (LeafPrimitive).
    const LeafPrimitives& leaf_primitives() const { return m_leaf; }
    const Scene& scene() const { return *m_scene; }
    BvhStats stats() const;

    // Depth-first, one ray at a time: the reference tracer's traversal.
    Hit intersect(const Ray& ray) const {
        NoTraversalCounts none;
        return intersect(ray, none);
    }
    // The same traversal, telling `counts` of every box and primitive test (TraversalCounts:
    // what recursive tracing costs, for benches and tests). Instantiated for the two policies.
    template <class Counts>
    Hit intersect(const Ray& ray, Counts& counts) const;
    bool occluded(const Ray& ray) const;

    // One primitive test (used by both tracers, so both compute the same bits).
    bool intersect_primitive(const RayPrecomp& r, uint32_t prim, float t_max, Hit& hit) const;
    // The same test of the primitive at position i of prim_ids, from leaf_primitives().
    bool intersect_leaf_primitive(const RayPrecomp& r, uint32_t i, float t_max, Hit& hit) const;
    // The same test of a triangle at position i, given its triangle_normal (a caller testing
    // many rays against one triangle computes it once).
    bool intersect_leaf_triangle(const RayPrecomp& r, uint32_t i, const TriangleNormal& normal,
                                 float t_max, Hit& hit) const;

  private:
    struct BuildInput;  // bvh.cpp: the primitives' bounds and centroids, the bins' scratch
    uint32_t build(uint32_t begin, uint32_t end, BuildInput& in, uint32_t depth);

    const Scene* m_scene = nullptr;
    BvhNodes m_nodes;
    std::vector<uint32_t> m_prim_ids;
    LeafPrimitives m_leaf;
};

// Front child first: the child on the side the direction comes from.
inline bool visit_right_first(const BvhNode& node, const Vec3& dir) { return dir[node.axis] < 0.f; }

}  // namespace sfx
