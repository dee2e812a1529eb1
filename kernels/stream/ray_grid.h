#pragma once
// RayGrid batching (Bikker, seeds/000 Sec. 3): secondary rays wait in queues attached to the
// cells of a coarse subdivision of the scene; a queue is traced as one stream against its
// cell's own hierarchy, and the rays that leave the cell without a hit move on to the queue of
// the next cell along the ray. Full queues go first, then the partial ones, largest first,
// until no ray is left (the paper's Algorithm 1, with its tail flushed at the end of each
// generation: a tile pass's trace must hold all of its own work).
//
// The cells are a top cut of the scene's BVH, not an octree: the highest nodes whose subtree
// holds at most `cell_prims` primitives (the paper's 4096 per octree leaf). The paper notes its
// octree replaces the first ~4 levels of the MBVH (Sec. 4.1); a cut is that replacement without
// a second build, so each cell's "mini-BVH" is the BVH's own subtree and the scene data keep
// their addresses whether batching is on or off (the scene-cache comparison sees only the order
// of the fetches change). Cut boxes may overlap rather than tile space, so the octree's
// neighbour links become a front-to-back walk: a ray's next cell is the one with the next
// (entry distance, cell index) along it that its current closest hit does not rule out, found
// by a branch-and-bound filter over the nodes above the cut (the raygrid_walk ops).
//
// Hits never change: a ray visits, in increasing entry order, every cell whose box its slab
// test passes with its current t, and t only shrinks, so every cell the plain traversal would
// enter with the final t is visited; the primitive tests keep the closest-hit tie rule.

#include <cstdint>
#include <vector>

#include "kernels/bvh.h"

namespace sfx {

class RayGrid {
  public:
    static constexpr uint32_t k_no_cell = ~0u;

    RayGrid(const Bvh& bvh, uint32_t cell_prims);

    // The cell a node of the cut is (cells are numbered in node order); k_no_cell for nodes
    // above the cut (and below it, where the walk never goes).
    uint32_t cell_of(uint32_t node) const { return m_cell[node]; }
    uint32_t cell_count() const { return uint32_t(m_cell_nodes.size()); }
    uint32_t cell_node(uint32_t cell) const { return m_cell_nodes[cell]; }
    uint32_t top_nodes() const { return m_top_nodes; }  // interior nodes above the cut
    double mean_cell_depth() const { return m_mean_depth; }

    // Where the ray leaves the box: the slab test's far distance without the t_max clamp,
    // rounded outwards as intersect_box rounds it, so a box inside this one never has a larger
    // entry than this exit (the walk prunes a subtree the ray leaves before its last cell).
    static float box_exit(const RayPrecomp& r, const Bounds3& b);

  private:
    std::vector<uint32_t> m_cell;        // per node
    std::vector<uint32_t> m_cell_nodes;  // per cell
    uint32_t m_top_nodes = 0;
    double m_mean_depth = 0.0;
};

}  // namespace sfx
