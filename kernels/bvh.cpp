#include "kernels/bvh.h"

#include <algorithm>
#include <array>
#include <stdexcept>

namespace sfx {

struct Bvh::BuildInput {
    const std::vector<Bounds3>& prim_bounds;
    const std::vector<Vec3>& centroids;
    const BvhBuildOptions& options;
    // Scratch of one node's SAH evaluation, reused by every node: per axis, each bin's bounds
    // and primitive count (axis-major); per split, the right side's area and count.
    std::vector<Bounds3> bin_bounds;
    std::vector<uint32_t> bin_counts;
    std::vector<float> right_area;
    std::vector<uint32_t> right_count;
};

Bvh::Bvh(const Scene& scene, const BvhBuildOptions& options) : m_scene(&scene) {
    if (options.max_leaf_size == 0 || options.max_leaf_size > 0xffff || options.bins < 2)
        throw std::invalid_argument("bvh: max_leaf_size must be in 1..65535 and bins >= 2");
    const uint32_t n = scene.primitive_count();
    std::vector<Bounds3> prim_bounds(n);
    std::vector<Vec3> centroids(n);
    for (uint32_t p = 0; p < n; ++p) {
        prim_bounds[p] = scene.primitive_bounds(p);
        centroids[p] = prim_bounds[p].center();
    }
    m_prim_ids.resize(n);
    for (uint32_t p = 0; p < n; ++p) m_prim_ids[p] = p;
    m_nodes.reserve(n ? 2 * n : 1);
    if (n == 0) {
        m_nodes.emplace_back();  // an empty leaf with empty bounds: every ray misses
        return;
    }
    const size_t bins = options.bins;
    BuildInput in{prim_bounds,
                  centroids,
                  options,
                  std::vector<Bounds3>(3 * bins),
                  std::vector<uint32_t>(3 * bins),
                  std::vector<float>(bins),
                  std::vector<uint32_t>(bins)};
    build(0, n, in, 0);
    m_leaf.resize(n);
    for (uint32_t i = 0; i < n; ++i) {
        const uint32_t prim = m_prim_ids[i];
        m_leaf[i].prim = prim;
        if (scene.is_sphere(prim)) continue;
        const Triangle& tri = scene.triangles[prim];
        m_leaf[i].p0 = scene.positions[tri.v0];
        m_leaf[i].p1 = scene.positions[tri.v1];
        m_leaf[i].p2 = scene.positions[tri.v2];
    }
}

uint32_t Bvh::build(uint32_t begin, uint32_t end, BuildInput& in, uint32_t depth) {
    const std::vector<Bounds3>& prim_bounds = in.prim_bounds;
    const std::vector<Vec3>& centroids = in.centroids;
    const BvhBuildOptions& options = in.options;
    const uint32_t index = uint32_t(m_nodes.size());
    m_nodes.emplace_back();
    Bounds3 bounds, centroid_bounds;
    for (uint32_t i = begin; i < end; ++i) {
        bounds.extend(prim_bounds[m_prim_ids[i]]);
        centroid_bounds.extend(centroids[m_prim_ids[i]]);
    }
    m_nodes[index].bounds = bounds;
    const uint32_t count = end - begin;
    auto make_leaf = [&] {
        m_nodes[index].first = begin;
        m_nodes[index].count = uint16_t(count);
        return index;
    };
    if (count == 1) return make_leaf();

    // Evaluate binned SAH on all three axes.
    const uint32_t bins = options.bins;
    const Vec3 extent = centroid_bounds.extent();
    float best_cost = INFINITY;
    int best_axis = -1;
    uint32_t best_split = 0;
    std::vector<float>& right_area = in.right_area;
    std::vector<uint32_t>& right_count = in.right_count;
    auto bin_of = [&](const Vec3& c, int axis) {
        const float rel = (c[axis] - centroid_bounds.lo[axis]) / extent[axis];
        return std::min(bins - 1, uint32_t(std::max(0.f, rel * float(bins))));
    };
    // One pass over the primitives bins them on every axis that has an extent.
    bool binned[3];
    for (int axis = 0; axis < 3; ++axis) binned[axis] = extent[axis] > 0.f;
    std::fill(in.bin_bounds.begin(), in.bin_bounds.end(), Bounds3{});
    std::fill(in.bin_counts.begin(), in.bin_counts.end(), 0u);
    // bin_of on the three axes at once: the same division and rounding per lane.
    typedef float Float4 __attribute__((vector_size(16)));
    const Float4 lo = {centroid_bounds.lo.x, centroid_bounds.lo.y, centroid_bounds.lo.z, 0.f};
    const Float4 scale = {extent.x, extent.y, extent.z, 1.f};
    for (uint32_t i = begin; i < end; ++i) {
        const uint32_t p = m_prim_ids[i];
        const Vec3& c = centroids[p];
        const Float4 rel = (Float4{c.x, c.y, c.z, 0.f} - lo) / scale * float(bins);
        for (int axis = 0; axis < 3; ++axis) {
            if (!binned[axis]) continue;
            const uint32_t b = axis * bins + std::min(bins - 1, uint32_t(std::max(0.f, rel[axis])));
            in.bin_bounds[b].extend(prim_bounds[p]);
            ++in.bin_counts[b];
        }
    }
    for (int axis = 0; axis < 3; ++axis) {
        if (!binned[axis]) continue;
        const Bounds3* bin_bounds = &in.bin_bounds[axis * size_t(bins)];
        const uint32_t* bin_counts = &in.bin_counts[axis * size_t(bins)];
        Bounds3 acc;
        uint32_t acc_count = 0;
        for (uint32_t b = bins - 1; b > 0; --b) {
            acc.extend(bin_bounds[b]);
            acc_count += bin_counts[b];
            right_area[b] = acc.surface_area();
            right_count[b] = acc_count;
        }
        acc = Bounds3{};
        acc_count = 0;
        for (uint32_t b = 1; b < bins; ++b) {  // split between bin b-1 and bin b
            acc.extend(bin_bounds[b - 1]);
            acc_count += bin_counts[b - 1];
            if (acc_count == 0 || right_count[b] == 0) continue;
            const float cost = acc.surface_area() * float(acc_count) +
                               right_area[b] * float(right_count[b]);
            if (cost < best_cost) {
                best_cost = cost;
                best_axis = axis;
                best_split = b;
            }
        }
    }

    const float area = bounds.surface_area();
    const float leaf_cost = options.intersection_cost * float(count);
    const float split_cost =
        options.traversal_cost + options.intersection_cost * best_cost / (area > 0.f ? area : 1.f);
    if (count <= options.max_leaf_size && (best_axis < 0 || leaf_cost <= split_cost))
        return make_leaf();

    uint32_t mid;
    int axis = best_axis;
    // Deep SAH chains (pathological inputs) switch to median splits, which bound the
    // remaining depth by log2(count) and so keep the traversal stacks below k_max_depth.
    if (depth >= k_sah_depth_limit) best_axis = -1;
    if (best_axis >= 0) {
        auto first_right = std::partition(
            m_prim_ids.begin() + begin, m_prim_ids.begin() + end,
            [&](uint32_t p) { return bin_of(centroids[p], best_axis) < best_split; });
        mid = uint32_t(first_right - m_prim_ids.begin());
    } else {
        // All centroids coincide, or the tree is too deep: median split along the widest
        // centroid axis (ids order equal keys, so the split is deterministic).
        axis = max_axis(extent);
        mid = begin + count / 2;
        std::nth_element(m_prim_ids.begin() + begin, m_prim_ids.begin() + mid,
                         m_prim_ids.begin() + end, [&](uint32_t a, uint32_t b) {
                             const float ca = centroids[a][axis], cb = centroids[b][axis];
                             return ca < cb || (ca == cb && a < b);
                         });
    }
    const uint32_t left = build(begin, mid, in, depth + 1);
    const uint32_t right = build(mid, end, in, depth + 1);
    if (left != BvhNode::left(index)) throw std::logic_error("bvh: left child must follow its parent");
    m_nodes[index].first = right;
    m_nodes[index].count = 0;
    m_nodes[index].axis = uint8_t(axis);
    return index;
}

namespace {
// The primitive test behind every entry point: `vertices` is the triangle's, or null for a
// sphere; `normal`, if not null, the triangle's triangle_normal.
bool test_primitive(const Scene& s, const RayPrecomp& r, uint32_t prim, const Vec3* p0,
                    const Vec3* p1, const Vec3* p2, const TriangleNormal* normal, float t_max,
                    Hit& hit) {
    float t, u = 0.f, v = 0.f;
    if (s.is_sphere(prim)) {
        if (!intersect_sphere(r, s.sphere(prim), t_max, t)) return false;
    } else if (!intersect_triangle(r, *p0, *p1, *p2,
                                   normal ? *normal : triangle_normal(*p0, *p1, *p2), t_max, t, u,
                                   v)) {
        return false;
    }
    if (!closer(t, prim, hit)) return false;
    hit.t = t;
    hit.u = u;
    hit.v = v;
    hit.prim = prim;
    return true;
}
}  // namespace

bool Bvh::intersect_primitive(const RayPrecomp& r, uint32_t prim, float t_max, Hit& hit) const {
    const Scene& s = *m_scene;
    if (s.is_sphere(prim))
        return test_primitive(s, r, prim, nullptr, nullptr, nullptr, nullptr, t_max, hit);
    const Triangle& tri = s.triangles[prim];
    return test_primitive(s, r, prim, &s.positions[tri.v0], &s.positions[tri.v1],
                          &s.positions[tri.v2], nullptr, t_max, hit);
}

bool Bvh::intersect_leaf_primitive(const RayPrecomp& r, uint32_t i, float t_max, Hit& hit) const {
    const LeafPrimitive& l = m_leaf[i];
    return test_primitive(*m_scene, r, l.prim, &l.p0, &l.p1, &l.p2, nullptr, t_max, hit);
}

bool Bvh::intersect_leaf_triangle(const RayPrecomp& r, uint32_t i, const TriangleNormal& normal,
                                  float t_max, Hit& hit) const {
    const LeafPrimitive& l = m_leaf[i];
    return test_primitive(*m_scene, r, l.prim, &l.p0, &l.p1, &l.p2, &normal, t_max, hit);
}

template <class Counts>
Hit Bvh::intersect(const Ray& ray, Counts& counts) const {
    Hit hit;
    if (!ray_is_valid(ray)) return hit;
    const RayPrecomp r(ray);
    float t_max = ray.t_max;
    std::array<uint32_t, k_max_depth + 1> stack;
    uint32_t top = 0;
    stack[top++] = 0;
    while (top > 0) {
        const uint32_t index = stack[--top];
        const BvhNode& node = m_nodes[index];
        counts.box();
        if (intersect_box(r, node.bounds, t_max) == INFINITY) continue;
        if (node.is_leaf()) {
            for (uint32_t i = node.first; i < node.first + node.count; ++i) {
                counts.primitive();
                if (intersect_leaf_primitive(r, i, t_max, hit)) t_max = hit.t;
            }
        } else {
            const bool right_first = visit_right_first(node, r.dir);
            const uint32_t left = BvhNode::left(index), right = node.right();
            stack[top++] = right_first ? left : right;  // back child, popped last
            stack[top++] = right_first ? right : left;
        }
    }
    return hit;
}

template Hit Bvh::intersect(const Ray&, NoTraversalCounts&) const;
template Hit Bvh::intersect(const Ray&, TraversalCounts&) const;

bool Bvh::occluded(const Ray& ray) const {
    if (!ray_is_valid(ray)) return false;
    const RayPrecomp r(ray);
    Hit hit;
    std::array<uint32_t, k_max_depth + 1> stack;
    uint32_t top = 0;
    stack[top++] = 0;
    while (top > 0) {
        const uint32_t index = stack[--top];
        const BvhNode& node = m_nodes[index];
        if (intersect_box(r, node.bounds, ray.t_max) == INFINITY) continue;
        if (node.is_leaf()) {
            for (uint32_t i = node.first; i < node.first + node.count; ++i)
                if (intersect_leaf_primitive(r, i, ray.t_max, hit)) return true;
        } else {
            stack[top++] = node.right();
            stack[top++] = BvhNode::left(index);
        }
    }
    return false;
}

BvhStats Bvh::stats() const {
    BvhStats s;
    s.nodes = m_nodes.size();
    s.bytes = m_nodes.size() * sizeof(BvhNode) + m_prim_ids.size() * sizeof(uint32_t);
    if (m_nodes.empty()) return s;
    const float root_area = m_nodes[0].bounds.surface_area();
    std::vector<std::pair<uint32_t, uint32_t>> stack{{0u, 0u}};
    uint64_t depth_sum = 0, size_sum = 0;
    double sah = 0.0;
    while (!stack.empty()) {
        auto [index, depth] = stack.back();
        stack.pop_back();
        const BvhNode& n = m_nodes[index];
        const double rel = root_area > 0.f ? n.bounds.surface_area() / root_area : 1.0;
        s.max_depth = std::max(s.max_depth, depth);
        if (n.is_leaf()) {
            ++s.leaves;
            depth_sum += depth;
            size_sum += n.count;
            s.max_leaf_size = std::max<uint32_t>(s.max_leaf_size, n.count);
            sah += rel * n.count;
        } else {
            sah += rel;
            stack.push_back({BvhNode::left(index), depth + 1});
            stack.push_back({n.right(), depth + 1});
        }
    }
    s.average_leaf_depth = s.leaves ? double(depth_sum) / double(s.leaves) : 0.0;
    s.average_leaf_size = s.leaves ? double(size_sum) / double(s.leaves) : 0.0;
    s.sah_cost = sah;
    return s;
}

}  // namespace sfx
