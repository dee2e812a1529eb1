#pragma once
// What a timing model must know of the workload besides the trace: the scene's features and
// the workload's options (they fix the ray record and which units exist) and the sizes of its
// data (they place scene data in memory). Built by whoever runs the tracer; the hardware model
// never sees the tracer.

#include <array>
#include <cstdint>
#include <memory>
#include <vector>

#include "kernels/trace.h"
#include "workloads/scene.h"

namespace sfx {

struct WorkloadShape {
    FeatureSet features;
    uint64_t triangles = 0;
    uint64_t spheres = 0;
    uint64_t bvh_nodes = 0;
    uint64_t vertices = 0;  // the meshes' (0: unknown, three a triangle)
    // Per BVH node, whether it is a leaf: the tree's shape, which a CPU core's traversal
    // branches on (hw_model/branch_predictor.h); the trace names the nodes tested, not their
    // kind. Null: unknown (a leaf is then told by the leaf tests that follow a passing node).
    std::shared_ptr<const std::vector<uint8_t>> node_leaf;
    uint32_t tile = 32;                // tile edge: tile^2 ray slots per pass
    bool primary_entry_aepsa = false;  // the workload searches primary entry points
    bool reorder_hit_point = false;    // the workload sorts streams by approximate hit point
    bool batching_raygrid = false;     // the workload batches secondary rays in cell queues

    uint32_t slots() const { return tile * tile; }
    // The operation kinds this scene can emit: their function units are elaborated, no others.
    std::array<bool, k_op_kind_count> needed_kinds() const;
};

inline std::array<bool, k_op_kind_count> WorkloadShape::needed_kinds() const {
    const bool lights = features.light_count > 0;
    std::array<bool, k_op_kind_count> k{};
    for (uint32_t i = 0; i < k_op_kind_count; ++i) {
        switch (k_op_kinds[i].feature) {
            case OpFeature::always:
                k[i] = true;
                break;
            case OpFeature::triangles:
                k[i] = features.triangles;
                break;
            case OpFeature::spheres:
                k[i] = features.spheres;
                break;
            case OpFeature::lights:
                k[i] = lights;
                break;
            case OpFeature::ambient:
                k[i] = features.ambient;
                break;
            case OpFeature::lambertian:
                k[i] = features.lambertian;
                break;
            case OpFeature::lambertian_and_lights:
                k[i] = features.lambertian && lights;
                break;
            case OpFeature::dielectric:
                k[i] = features.dielectric;
                break;
            case OpFeature::glossy:
                k[i] = features.glossy;
                break;
            case OpFeature::primary_entry_aepsa:
                k[i] = primary_entry_aepsa;
                break;
            case OpFeature::reorder_hit_point:
                k[i] = reorder_hit_point;
                break;
            case OpFeature::batching_raygrid:
                k[i] = batching_raygrid;
                break;
        }
    }
    return k;
}

}  // namespace sfx
