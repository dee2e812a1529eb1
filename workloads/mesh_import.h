#pragma once
// Triangle meshes from files (OBJ, PLY, glTF, and whatever else assimp reads), flattened:
// node transforms applied, polygons triangulated, points and lines dropped.

#include <cstdint>
#include <string>
#include <vector>

#include "base/vec.h"

namespace sfx {

struct TriangleMesh {
    std::vector<Vec3> positions;
    std::vector<uint32_t> indices;  // three per triangle
    // What was read past and how ("line 3: 'Created by ...' is no PLY keyword; read as a comment").
    std::vector<std::string> warnings;

    size_t triangle_count() const { return indices.size() / 3; }
};

// Throws std::runtime_error with assimp's message on a missing or unreadable file, or one
// without triangles; the scene loader turns that into an InputError naming the scene file.
TriangleMesh import_mesh(const std::string& path);

}  // namespace sfx
