#include "workloads/mesh_import.h"

#include <assimp/postprocess.h>
#include <assimp/scene.h>

#include <assimp/Importer.hpp>
#include <cctype>
#include <cerrno>
#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <sstream>
#include <stdexcept>

#include "workloads/user_files.h"

namespace sfx {
namespace {

bool finite_number(const std::string& token) {
    if (token.empty()) return false;
    char* end = nullptr;
    errno = 0;
    const float v = std::strtof(token.c_str(), &end);
    return *end == '\0' && std::isfinite(v) &&  // underflow to 0 is harmless
           token.find_first_of("xXpP") == std::string::npos;  // no hex floats either
}

// assimp's number reader takes "1.#INF" (an old C library's infinity) as 1 and "0x1p200" as 0:
// in the text formats, every coordinate must be a finite decimal number before assimp reads it.
// OBJ: every number of a `v` line; ASCII PLY: every token after the header.
void check_text_coordinates(const std::string& path) {
    std::string ext = std::filesystem::path(path).extension().string();
    for (char& c : ext) c = char(std::tolower(static_cast<unsigned char>(c)));
    const std::string text = read_input_file(path, "mesh");
    const bool obj = ext == ".obj";
    const bool ascii_ply = text.compare(0, 3, "ply") == 0 && text.find("format ascii") < text.find("end_header");
    if (!obj && !ascii_ply) return;
    size_t body = 0;
    int line = 1;
    if (ascii_ply) {
        const size_t header_end = text.find("end_header");
        if (header_end == std::string::npos) return;  // assimp reports it
        for (size_t i = 0; i < header_end; ++i) line += text[i] == '\n';
        body = text.find('\n', header_end);
        if (body == std::string::npos) return;
        ++body;
        ++line;
    }
    std::istringstream in(text.substr(body));
    for (std::string row; std::getline(in, row); ++line) {
        std::istringstream tokens(row);
        std::string token;
        if (obj && (!(tokens >> token) || token != "v")) continue;
        while (tokens >> token) {
            if (obj && token[0] == '#') break;  // a comment
            if (!finite_number(token))
                throw std::runtime_error("line " + std::to_string(line) + ": '" + token +
                                         "' is not a finite number");
        }
    }
}

}  // namespace

TriangleMesh import_mesh(const std::string& path) {
    check_regular_file(path, "mesh");  // assimp would block on a FIFO
    check_text_coordinates(path);
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
        for (unsigned v = 0; v < am->mNumVertices; ++v) {
            const aiVector3D& p = am->mVertices[v];
            if (!std::isfinite(p.x) || !std::isfinite(p.y) || !std::isfinite(p.z))
                throw std::runtime_error("vertex " + std::to_string(mesh.positions.size()) +
                                         " has a non-finite coordinate");
            mesh.positions.emplace_back(p.x, p.y, p.z);
        }
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
