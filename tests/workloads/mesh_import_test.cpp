// Mesh import through assimp: tiny OBJ and PLY files written here, loaded directly and from a
// scene file (relative path, transform).

#include "workloads/mesh_import.h"

#include <catch2/catch.hpp>
#include <filesystem>
#include <fstream>

#include "tests/temp_dir.h"
#include "workloads/scene_loader.h"

using namespace sfx;
namespace fs = std::filesystem;

namespace {

// This process's own directory: CTest runs the cases in parallel processes.
fs::path test_dir() {
    static const TempDir dir("sfx-mesh-import-test");
    fs::create_directories(dir.path / "meshes");
    return dir.path;
}

// Writes `text` byte for byte to `name` in the test directory and imports it.
TriangleMesh import_text(const std::string& name, const std::string& text) {
    const fs::path p = test_dir() / name;
    std::ofstream(p, std::ios::binary) << text;
    return import_mesh(p.string());
}

// A unit square made of one quad face (triangulated on import) plus one triangle.
const char* const k_obj =
    "# square and a triangle\n"
    "v 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nv 0 0 1\n"
    "f 1 2 3 4\n"
    "f 1 2 5\n";

const char* const k_ply =
    "ply\nformat ascii 1.0\nelement vertex 4\nproperty float x\nproperty float y\n"
    "property float z\nelement face 2\nproperty list uchar int vertex_indices\nend_header\n"
    "0 0 0\n2 0 0\n2 2 0\n0 2 0\n3 0 1 2\n3 0 2 3\n";

}  // namespace

TEST_CASE("mesh import: OBJ polygons are triangulated", "[workloads]") {
    const fs::path p = test_dir() / "meshes" / "square.obj";
    std::ofstream(p) << k_obj;
    const TriangleMesh m = import_mesh(p.string());
    CHECK(m.triangle_count() == 3);
    CHECK(m.positions.size() >= 5);
    Bounds3 b;
    for (uint32_t i : m.indices) b.extend(m.positions.at(i));
    CHECK(b.lo == Vec3(0.f));
    CHECK(b.hi == Vec3(1.f));
}

TEST_CASE("mesh import: PLY", "[workloads]") {
    const fs::path p = test_dir() / "meshes" / "square.ply";
    std::ofstream(p) << k_ply;
    const TriangleMesh m = import_mesh(p.string());
    CHECK(m.triangle_count() == 2);
    float area = 0.f;
    for (size_t t = 0; t < m.indices.size(); t += 3) {
        const Vec3 a = m.positions[m.indices[t]], b = m.positions[m.indices[t + 1]];
        const Vec3 c = m.positions[m.indices[t + 2]];
        area += 0.5f * length(cross(b - a, c - a));
    }
    CHECK(area == Approx(4.f));
}

TEST_CASE("mesh import: glTF with an embedded buffer", "[workloads]") {
    // One triangle (0,0,0) (1,0,0) (0,1,0), positions base64-encoded in a data URI.
    const fs::path p = test_dir() / "meshes" / "triangle.gltf";
    std::ofstream(p) << R"({"asset": {"version": "2.0"}, "scene": 0, "scenes": [{"nodes": [0]}],
 "nodes": [{"mesh": 0, "translation": [0, 0, 2]}],
 "meshes": [{"primitives": [{"attributes": {"POSITION": 0}, "mode": 4}]}],
 "buffers": [{"byteLength": 36,
   "uri": "data:application/octet-stream;base64,AAAAAAAAAAAAAAAAAACAPwAAAAAAAAAAAAAAAAAAgD8AAAAA"}],
 "bufferViews": [{"buffer": 0, "byteOffset": 0, "byteLength": 36}],
 "accessors": [{"bufferView": 0, "componentType": 5126, "count": 3, "type": "VEC3",
   "min": [0, 0, 0], "max": [1, 1, 0]}]})";
    const TriangleMesh m = import_mesh(p.string());
    REQUIRE(m.triangle_count() == 1);
    Bounds3 b;
    for (uint32_t i : m.indices) b.extend(m.positions.at(i));
    CHECK(b.lo == Vec3(0.f, 0.f, 2.f));  // the node's translation is applied
    CHECK(b.hi == Vec3(1.f, 1.f, 2.f));
}

TEST_CASE("mesh import: missing file throws", "[workloads]") {
    CHECK_THROWS(import_mesh((test_dir() / "meshes" / "nothing_here.obj").string()));
}

TEST_CASE("mesh import: scene files place meshes relative to themselves", "[workloads]") {
    const fs::path dir = test_dir();
    std::ofstream(dir / "meshes" / "square.obj") << k_obj;
    std::ofstream(dir / "meshes" / "square.ply") << k_ply;
    const fs::path scene = dir / "meshes.scene.yaml";
    std::ofstream(scene) << "version: 1\n"
                            "camera: {eye: [0, 0, 5], look_at: [0, 0, 0]}\n"
                            "materials: [{name: m, kind: lambertian}]\n"
                            "objects:\n"
                            "  - {type: mesh, material: m, file: meshes/square.obj,\n"
                            "     transform: {scale: [2, 2, 2], translate: [0, 0, -3]}}\n"
                            "  - {type: mesh, material: m, file: meshes/square.ply}\n";
    const Scene s = load_scene(scene.string());
    CHECK(s.triangles.size() == 5);
    Bounds3 b;
    for (uint32_t p = 0; p < 3; ++p) b.extend(s.primitive_bounds(p));
    CHECK(b.lo == Vec3(0.f, 0.f, -3.f));
    CHECK(b.hi == Vec3(2.f, 2.f, -1.f));
    CHECK(s.lights.empty());
}

// Found by the mesh_ply fuzzer (the inputs are in tests/fuzz/regressions/mesh_ply/): assimp
// loops for ever on a malformed PLY header, and aborts the process on a face without indices.
TEST_CASE("mesh import: a malformed PLY header is refused, never read for ever", "[workloads]") {
    using Catch::Matchers::Contains;
    const std::string body = "0 0 0\n1 0 0\n0 1 0\n3 0 1 2\n";
    const std::string header =
        "element vertex 3\nproperty float x\nproperty float y\n"
        "property float z\nelement face 1\n"
        "property list uchar int vertex_indices\n";
    CHECK(import_text("ok.ply", "ply\nformat ascii 1.0\n" + header + "end_header\n" + body)
              .triangle_count() == 1);
    CHECK_THROWS_WITH(import_text("a.ply", "ply\nformat binary_little_endian 1.0\nply\n" + header +
                                               "end_header\n"),
                      Contains("line 3: not a PLY header"));
    CHECK_THROWS_WITH(import_text("b.ply", "ply\nformat ascii 1.0\n" + header + body),
                      Contains("no end_header"));
    CHECK_THROWS_WITH(
        import_text("c.ply", "ply\nformat ascii 1.0\nelement vertex 3\nproperty float\n" + header +
                                 "end_header\n" + body),
        Contains("line 4: not a PLY header: expected 'property TYPE NAME'"));
    // A line that is no PLY keyword is read past, as assimp does (Blender writes a bare
    // "Created by Blender ..." line), with a warning naming it; among an element's properties
    // it is refused, as assimp would skip the properties after it and misread the body.
    const TriangleMesh blender = import_text(
        "d.ply", "ply\nformat ascii 1.0\nCreated by Blender 3.6.0 - www.blender.org\n" + header +
                     "elementr\nend_header\n" + body);
    CHECK(blender.triangle_count() == 1);
    REQUIRE(blender.warnings.size() == 2);
    CHECK_THAT(blender.warnings[0], Contains("line 3: 'Created by Blender 3.6.0 - www.blender.org' is no PLY keyword"));
    CHECK_THAT(blender.warnings[1], Contains("line 10: 'elementr'"));
    CHECK(blender.positions == import_text("ok.ply", "ply\nformat ascii 1.0\n" + header + "end_header\n" + body).positions);
    CHECK_THROWS_WITH(
        import_text("d2.ply", "ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\nCreated by\n"
                              "property float y\nproperty float z\nelement face 1\n"
                              "property list uchar int vertex_indices\nend_header\n" + body),
        Contains("line 5: not a PLY header: a line that is no PLY keyword among the properties of element 'vertex'"));
    CHECK_THROWS_WITH(import_text("d3.ply", "ply\nformat ascii 1.0\nformat ascii 1.0\n" + header +
                                                "end_header\n" + body),
                      Contains("line 3: not a PLY header: a second 'format' line"));
    CHECK_THROWS_WITH(
        import_text("e.ply", "ply\nformat ascii 1.0\n" + header + "end_header " + body),
        Contains("line 9: not a PLY header: end_header must end its line"));
    CHECK_THROWS_WITH(
        import_text(
            "f.ply",
            std::string("ply\nformat ascii 1.0\nelement vertex 3\nproperty float \0x\n", 56) +
                "end_header\n" + body),
        Contains("line 4: not a PLY header: a control character"));
}

TEST_CASE("mesh import: a PLY face without indices or with an index past the vertices is refused",
          "[workloads]") {
    using Catch::Matchers::Contains;
    const std::string header =
        "ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\nproperty float y\n"
        "property float z\nelement face 2\nproperty list uchar int vertex_indices\nend_header\n"
        "0 0 0\n1 0 0\n0 1 0\n3 0 1 2\n";
    CHECK_THROWS_WITH(import_text("empty_face.ply", header + "0\n"),
                      Contains("face 1 has no vertices"));
    CHECK_THROWS_WITH(import_text("far_index.ply", header + "3 0 1 7\n"),
                      Contains("face 1 names vertex 7 of 3"));
}

// Found by the mesh_ply fuzzer (regressions/mesh_ply/): assimp sizes its arrays from the
// counts a PLY file states, so a count of billions in a small file took gigabytes.
TEST_CASE("mesh import: a PLY count larger than the file is refused before assimp reads it",
          "[workloads]") {
    using Catch::Matchers::Contains;
    const std::string vertices =
        "element vertex 3\nproperty float x\nproperty float y\nproperty float z\n";
    const std::string ascii = "ply\nformat ascii 1.0\n" + vertices +
                              "element face 1\nproperty list uint int vertex_indices\nend_header\n"
                              "0 0 0\n1 0 0\n0 1 0\n";
    CHECK(import_text("ok.ply", ascii + "3 0 1 2\n").triangle_count() == 1);
    CHECK_THROWS_WITH(import_text("long_list.ply", ascii + "4000000000 0 1 2\n"),
                      Contains("line 13: a list of 4000000000 items, more than its line holds"));
    CHECK_THROWS_WITH(import_text("past_type.ply", ascii + "8888888888888888888888888 0 1 2\n"),
                      Contains("line 13: '8888888888888888888888888' is not a list length"));
    CHECK_THROWS_WITH(import_text("short.ply", ascii),
                      Contains("the body ends before instance 0 of the 1 'face' elements"));
    CHECK_THROWS_WITH(
        import_text("many.ply", "ply\nformat ascii 1.0\n" + vertices +
                                    "element face 4000000000\nproperty list uchar int v\n"
                                    "end_header\n0 0 0\n1 0 0\n0 1 0\n3 0 1 2\n"),
        Contains("the body ends before instance 1 of the 4000000000 'face' elements"));
    CHECK_THROWS_WITH(import_text("empty_elements.ply", "ply\nformat ascii 1.0\n" + vertices +
                                                            "element edge 4000000000\n"
                                                            "end_header\n0 0 0\n1 0 0\n0 1 0\n"),
                      Contains("'edge' states 4000000000 instances without properties"));
    CHECK_THROWS_WITH(import_text("float_count.ply",
                                  "ply\nformat ascii 1.0\n" + vertices +
                                      "element face 1\nproperty list float int v\nend_header\n"),
                      Contains("line 8: not a PLY header: a list's count type must be an integer"));
    CHECK_THROWS_WITH(
        import_text("digit_name.ply",
                    "ply\nformat ascii 1.0\nelement 4294967295vertex 3\n"
                    "property float x\nend_header\n0\n1\n2\n"),
        Contains("line 3: not a PLY header: an element's name must not start with a digit"));
    // Binary: three vertices, then a face whose uint count says four billion.
    std::string binary = "ply\nformat binary_little_endian 1.0\n" + vertices +
                         "element face 1\nproperty list uint int vertex_indices\nend_header\n";
    const size_t body = binary.size();
    binary += std::string(36, '\0') + std::string("\x00\x28\x6b\xee", 4) + std::string(12, '\0');
    CHECK_THROWS_WITH(import_text("long_list_binary.ply", binary),
                      Contains("byte " + std::to_string(body + 36) +
                               ": a list of 4000000000 items, more than the file has left"));
    binary.replace(body + 36, 4, std::string("\x03\x00\x00\x00", 4));
    binary.replace(body + 40, 12,
                   std::string("\x00\x00\x00\x00\x01\x00\x00\x00\x02\x00\x00\x00", 12));
    CHECK(import_text("ok_binary.ply", binary).triangle_count() == 1);
    std::string crlf = binary;
    crlf.replace(body - 1, 1, "\r\n");
    CHECK_THROWS_WITH(import_text("crlf_binary.ply", crlf),
                      Contains("line 9: not a PLY header: a binary body's end_header line must "
                               "end with a bare LF"));
    CHECK_THROWS_WITH(import_text("short_binary.ply", binary.substr(0, binary.size() - 1)),
                      Contains("a list of 3 items, more than the file has left"));
}

// Found by fuzzing (a corrupted heap, regressions/mesh_ply/): assimp 5.2 sizes its vertex and
// face arrays by the first element of each kind and writes later ones past them; it reads a
// face's texcoord list of six to eight items past the face's indices.
TEST_CASE("mesh import: PLY layouts that assimp writes or reads out of bounds are refused",
          "[workloads]") {
    using Catch::Matchers::Contains;
    const std::string vertex = "property float x\nproperty float y\nproperty float z\n";
    CHECK_THROWS_WITH(
        import_text("two_vertex.ply", "ply\nformat ascii 1.0\nelement vertex 1\n" + vertex +
                                          "element vertex 3\n" + vertex + "end_header\n" +
                                          "0 0 0\n0 0 0\n1 0 0\n0 1 0\n"),
        Contains("line 7: not a PLY header: a second element 'vertex'"));
    const std::string head = "ply\nformat ascii 1.0\nelement vertex 3\n" + vertex;
    CHECK_THROWS_WITH(
        import_text("face_strips.ply",
                    head + "element face 1\nproperty list uchar int vertex_indices\n"
                           "element tristrips 1\nproperty list int int vertex_indices\n"
                           "end_header\n0 0 0\n1 0 0\n0 1 0\n3 0 1 2\n3 0 1 2\n"),
        Contains("line 9: not a PLY header: both 'face' and 'tristrips' elements"));
    const std::string faces = head +
                              "element face 1\nproperty list uchar int vertex_indices\n"
                              "property list uchar float texcoord\nend_header\n"
                              "0 0 0\n1 0 0\n0 1 0\n";
    CHECK(import_text("texcoord_ok.ply", faces + "3 0 1 2 6 0 0 1 0 0 1\n").triangle_count() == 1);
    CHECK_THROWS_WITH(
        import_text("texcoord_long.ply", faces + "3 0 1 2 8 0 0 1 0 0 1 1 1\n"),
        Contains("line 14: a face's texcoord list of 8 items, more than two for each of its 3"));
}

// Found by fuzzing (regressions/mesh_ply/): assimp 5.2 reads no instances of an element whose
// name it does not know, so the next element reads that element's numbers.
TEST_CASE("mesh import: a PLY body is checked as assimp reads it", "[workloads]") {
    using Catch::Matchers::Contains;
    const std::string vertex =
        "element vertex 3\nproperty float x\nproperty float y\n"
        "property float z\n";
    // A trailing unknown element: assimp reads none of it; the mesh is whole.
    CHECK(import_text("trailing.ply", "ply\nformat ascii 1.0\n" + vertex +
                                          "element face 1\nproperty list uchar int vertex_indices\n"
                                          "element range_grid 2\nproperty uchar n\nend_header\n"
                                          "0 0 0\n1 0 0\n0 1 0\n3 0 1 2\n1\n1\n")
              .triangle_count() == 1);
    // An unknown element before the faces: its numbers are read as the faces'.
    CHECK_THROWS_WITH(
        import_text("verpex.ply", "ply\nformat ascii 1.0\n" + vertex +
                                      "element verpex 1\nproperty uchar n\nelement face 1\n"
                                      "property list uchar uint vertex_indices\nend_header\n"
                                      "0 0 0\n1 0 0\n0 1 0\n7\n3 0 1 2\n"),
        Contains("line 15: a list of 7 items, more than its line holds"));
    // assimp reads an instance from one line: a list's items must be on it.
    const std::string faces = "ply\nformat ascii 1.0\n" + vertex +
                              "element face 1\nproperty list uchar uint vertex_indices\n"
                              "end_header\n0 0 0\n1 0 0\n0 1 0\n";
    CHECK_THROWS_WITH(import_text("split.ply", faces + "3\n0 1 2\n"),
                      Contains("line 13: a list of 3 items, more than its line holds"));
    CHECK_THROWS_WITH(import_text("nul.ply", faces + std::string("3 0 1 2\0 9\n", 11)),
                      Contains("line 13: a control character in the body"));
    CHECK_THROWS_WITH(import_text("few.ply", faces.substr(0, faces.size() - 2) + "\n3 0 1 2\n"),
                      Contains("line 12: too few numbers for instance 2 of the 'vertex' elements"));
    CHECK_THROWS_WITH(import_text("case.ply",
                                  "ply\nformat ascii 1.0\nelement Vertex 3\n"
                                  "property float x\nend_header\n0\n1\n2\n"),
                      Contains("line 3: not a PLY header: element 'Vertex' is not supported"));
}
