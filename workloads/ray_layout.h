#pragma once
// The ray record: what the hardware keeps per ray in its ray buffer, derived from a scene's
// feature set. Its size decides how many rays a ray buffer of a given capacity holds.

#include <cstdint>
#include <string>
#include <vector>

#include "workloads/scene.h"

namespace sfx {

struct RayField {
    std::string name;
    uint32_t bytes = 0;
    std::string why;
};

// Fields in buffer order; only those the scene's features need.
std::vector<RayField> ray_record_fields(const FeatureSet& features);
uint32_t ray_record_bytes(const FeatureSet& features);

}  // namespace sfx
