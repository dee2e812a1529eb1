#include "kernels/stream/ray_grid.h"

#include <algorithm>
#include <cmath>

namespace sfx {

RayGrid::RayGrid(const Bvh& bvh, uint32_t cell_prims) {
    const BvhNodes& nodes = bvh.nodes();
    m_cell.assign(nodes.size(), k_no_cell);
    if (nodes.empty()) return;
    // Primitives under each node; children come after their parent (depth-first build).
    std::vector<uint64_t> prims(nodes.size(), 0);
    for (size_t i = nodes.size(); i-- > 0;) {
        const BvhNode& n = nodes[i];
        prims[i] = n.is_leaf() ? n.count : prims[BvhNode::left(uint32_t(i))] + prims[n.right()];
    }
    std::vector<std::pair<uint32_t, uint32_t>> stack = {{0u, 0u}};  // (node, depth)
    uint64_t depth_sum = 0;
    std::vector<std::pair<uint32_t, uint32_t>> cut;
    while (!stack.empty()) {
        const auto [i, depth] = stack.back();
        stack.pop_back();
        const BvhNode& n = nodes[i];
        if (n.is_leaf() || prims[i] <= std::max(1u, cell_prims)) {
            cut.push_back({i, depth});
            continue;
        }
        ++m_top_nodes;
        stack.push_back({n.right(), depth + 1});
        stack.push_back({BvhNode::left(i), depth + 1});
    }
    std::sort(cut.begin(), cut.end());
    for (const auto& [node, depth] : cut) {
        m_cell[node] = uint32_t(m_cell_nodes.size());
        m_cell_nodes.push_back(node);
        depth_sum += depth;
    }
    m_mean_depth = double(depth_sum) / double(cut.size());
}

float RayGrid::box_exit(const RayPrecomp& r, const Bounds3& b) {
    // intersect.h's slab_test<1> far side, the same operations in the same order.
    float t1 = INFINITY;
    for (int a = 0; a < 3; ++a) {
        const bool negative = std::signbit(r.inv_dir[a]);
        float t_far = ((negative ? b.lo[a] : b.hi[a]) - r.org[a]) * r.inv_dir[a];
        t_far = std::isnan(t_far) ? INFINITY : t_far * k_slab_far_scale;
        t1 = t_far < t1 ? t_far : t1;
    }
    return t1;
}

}  // namespace sfx
