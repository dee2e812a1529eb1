#include "workloads/mesh_import.h"

#include <assimp/postprocess.h>
#include <assimp/scene.h>

#include <assimp/Importer.hpp>
#include <stdexcept>

namespace sfx {

TriangleMesh import_mesh(const std::string& path) {
    Assimp::Importer importer;
    // Points and lines are removed rather than kept as degenerate triangles; vertices are
    // joined so that shared edges stay watertight for the triangle test.
    importer.SetPropertyInteger(AI_CONFIG_PP_SBP_REMOVE, aiPrimitiveType_POINT | aiPrimitiveType_LINE);
    const aiScene* scene = importer.ReadFile(
        path, aiProcess_Triangulate | aiProcess_JoinIdenticalVertices |
                  aiProcess_PreTransformVertices | aiProcess_SortByPType);
    if (!scene || (scene->mFlags & AI_SCENE_FLAGS_INCOMPLETE))
        throw std::runtime_error(std::string("cannot import: ") + importer.GetErrorString());
    TriangleMesh mesh;
    for (unsigned m = 0; m < scene->mNumMeshes; ++m) {
        const aiMesh* am = scene->mMeshes[m];
        const uint32_t base = uint32_t(mesh.positions.size());
        for (unsigned v = 0; v < am->mNumVertices; ++v)
            mesh.positions.emplace_back(am->mVertices[v].x, am->mVertices[v].y, am->mVertices[v].z);
        for (unsigned f = 0; f < am->mNumFaces; ++f) {
            const aiFace& face = am->mFaces[f];
            if (face.mNumIndices != 3) continue;
            for (int k = 0; k < 3; ++k) mesh.indices.push_back(base + face.mIndices[k]);
        }
    }
    if (mesh.indices.empty()) throw std::runtime_error("the file holds no triangles");
    return mesh;
}

}  // namespace sfx
