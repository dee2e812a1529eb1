#include "workloads/mesh_import.h"

#include <assimp/postprocess.h>
#include <assimp/scene.h>

#include <algorithm>
#include <assimp/Importer.hpp>
#include <cctype>
#include <cerrno>
#include <cmath>
#include <cstdint>
#include <cstdlib>
#include <filesystem>
#include <map>
#include <set>
#include <sstream>
#include <stdexcept>
#include <vector>

#include "base/user_files.h"

namespace sfx {
namespace {

bool finite_number(const std::string& token) {
    if (token.empty()) return false;
    char* end = nullptr;
    errno = 0;
    const float v = std::strtof(token.c_str(), &end);
    return *end == '\0' && std::isfinite(v) &&                // underflow to 0 is harmless
           token.find_first_of("xXpP") == std::string::npos;  // no hex floats either
}

// A PLY header's elements, as far as the body checks need them.
struct PlyProperty {
    bool list = false;
    std::string count_type;  // a list's count type
    std::string value_type;  // the property's type, or a list's item type
    std::string name;
};
struct PlyElement {
    std::string name;
    uint64_t count = 0;
    std::vector<PlyProperty> properties;
};
struct PlyLayout {
    std::string format;
    std::vector<PlyElement> elements;
    size_t body = 0;  // offset of the first byte after the end_header line
    int body_line = 0;
};

// Bytes of a PLY scalar type in a binary body.
size_t ply_type_size(const std::string& type) {
    static const std::map<std::string, size_t> sizes = {
        {"char", 1},  {"uchar", 1},   {"int8", 1},   {"uint8", 1},  {"short", 2}, {"ushort", 2},
        {"int16", 2}, {"uint16", 2},  {"int", 4},    {"uint", 4},   {"int32", 4}, {"uint32", 4},
        {"float", 4}, {"float32", 4}, {"double", 8}, {"float64", 8}};
    return sizes.at(type);
}

// Largest list length a count type can hold.
uint64_t ply_count_max(const std::string& type) {
    switch (ply_type_size(type)) {
        case 1:
            return type == "char" || type == "int8" ? 127 : 255;
        case 2:
            return type == "short" || type == "int16" ? 32767 : 65535;
        default:
            return type == "int" || type == "int32" ? 2147483647ull : 4294967295ull;
    }
}

// assimp 5.2 loops for ever on some malformed PLY headers (no end_header) and misreads others:
// the header is checked against the PLY grammar first. A line that starts with no PLY keyword
// (Blender writes a bare "Created by Blender ..." line) is read past by assimp, as a comment, and
// accepted with a warning where that is harmless: not among an element's properties, whose
// list it would cut short (assimp then skips the properties after it and misreads the body).
PlyLayout check_ply_header(const std::string& text, std::vector<std::string>* warnings) {
    static const std::set<std::string> types = {
        "char", "uchar", "short", "ushort", "int",   "uint",   "float",   "double",
        "int8", "uint8", "int16", "uint16", "int32", "uint32", "float32", "float64"};
    static const std::set<std::string> count_types = {"char",  "uchar",  "short", "ushort",
                                                      "int",   "uint",   "int8",  "uint8",
                                                      "int16", "uint16", "int32", "uint32"};
    auto fail = [](int line, const std::string& what) {
        throw std::runtime_error("line " + std::to_string(line) + ": not a PLY header: " + what);
    };
    const size_t header_end = text.find("end_header");
    if (header_end == std::string::npos) fail(1, "no end_header");
    // A header is printable text; assimp 5.2 reads a binary body past its buffer when the
    // end_header line runs on into it (found by fuzzing: regressions/mesh_ply/).
    for (size_t i = 0; i < header_end; ++i) {
        const unsigned char c = static_cast<unsigned char>(text[i]);
        if ((c < 0x20 && c != '\n' && c != '\r' && c != '\t') || c == 0x7f)
            fail(1 + int(std::count(text.begin(), text.begin() + long(i), '\n')),
                 "a control character in the header");
    }
    const size_t after = header_end + std::string("end_header").size();
    if (text.compare(after, 1, "\n") != 0 && text.compare(after, 2, "\r\n") != 0)
        fail(1 + int(std::count(text.begin(), text.begin() + long(header_end), '\n')),
             "end_header must end its line");
    PlyLayout layout;
    layout.body = text.find('\n', after) + 1;
    static const std::set<std::string> keywords = {"ply",      "format",  "element",   "property",
                                                   "comment",  "obj_info", "end_header"};
    int free_text_line = 0;  // the last line read past as a comment, until an element starts
    std::istringstream in(text.substr(0, header_end));
    std::string row;
    int line = 0;
    while (std::getline(in, row)) {
        ++line;
        if (!row.empty() && row.back() == '\r') row.pop_back();
        std::istringstream tokens(row);
        std::vector<std::string> t;
        for (std::string w; tokens >> w;) t.push_back(w);
        if (line == 1) {
            if (row != "ply") fail(line, "the first line must be 'ply'");
        } else if (line == 2) {
            if (t.size() != 3 || t[0] != "format" || t[2] != "1.0" ||
                (t[1] != "ascii" && t[1] != "binary_little_endian" && t[1] != "binary_big_endian"))
                fail(line,
                     "the second line must be 'format ascii|binary_little_endian|binary_big_endian "
                     "1.0'");
            layout.format = t[1];
        } else if (t.empty() || t[0] == "comment" || t[0] == "obj_info") {
        } else if (!keywords.count(t[0]) && line > 2) {
            free_text_line = line;
            if (warnings)
                warnings->push_back("line " + std::to_string(line) + ": '" + row.substr(0, 60) +
                                    "' is no PLY keyword; read as a comment");
        } else if (t[0] == "element") {
            free_text_line = 0;
            if (t.size() != 3 || t[2].find_first_not_of("0123456789") != std::string::npos ||
                t[2].size() > 10)
                fail(line, "expected 'element NAME COUNT'");
            // assimp 5.2 reads the count of an element whose name it does not know from the
            // front of the name (found by fuzzing: "element 4294967295vertex 5").
            if (std::isdigit(static_cast<unsigned char>(t[1][0])))
                fail(line, "an element's name must not start with a digit");
            // assimp 5.2 sizes its vertex and face arrays by the first such element and
            // writes every later one's instances past them (found by fuzzing: a corrupted
            // heap; regressions/mesh_ply/).
            for (const PlyElement& e : layout.elements) {
                if (e.name == t[1]) fail(line, "a second element '" + t[1] + "'");
                if ((e.name == "face" && t[1] == "tristrips") ||
                    (e.name == "tristrips" && t[1] == "face"))
                    fail(line, "both 'face' and 'tristrips' elements");
            }
            // assimp 5.2 reads the count of an element only for the names it knows; for any
            // other it reads the front of the name (0, as no name starts with a digit) and so
            // no instances: the body is walked as assimp will read it (found by fuzzing).
            static const std::set<std::string> known = {"vertex", "face", "tristrips", "edge",
                                                        "material"};
            std::string lower = t[1];
            for (char& c : lower) c = char(std::tolower(static_cast<unsigned char>(c)));
            if (lower == "texturefile" || (!known.count(t[1]) && known.count(lower)))
                fail(line, "element '" + t[1] + "' is not supported");
            layout.elements.push_back({t[1], known.count(t[1]) ? std::stoull(t[2]) : 0, {}});
        } else if (t[0] == "property") {
            const bool list =
                t.size() == 5 && t[1] == "list" && types.count(t[2]) && types.count(t[3]);
            if (layout.elements.empty() || !(list || (t.size() == 3 && types.count(t[1]))))
                fail(line,
                     "expected 'property TYPE NAME' or 'property list TYPE TYPE NAME' after an "
                     "element");
            if (free_text_line)
                fail(free_text_line, "a line that is no PLY keyword among the properties of element '" +
                                         layout.elements.back().name +
                                         "' (assimp would skip the properties after it)");
            if (list && !count_types.count(t[2]))
                fail(line, "a list's count type must be an integer type, not '" + t[2] + "'");
            layout.elements.back().properties.push_back(list ? PlyProperty{true, t[2], t[3], t[4]}
                                                             : PlyProperty{false, "", t[1], t[2]});
        } else {
            fail(line, "a second '" + t[0] + "' line");
        }
    }
    // end_header must be a line of its own, after a newline.
    if (header_end == 0 || text[header_end - 1] != '\n')
        fail(line + 1, "end_header must start a line");
    // assimp 5.2 starts a binary body right after the first line-end byte: at the LF of a CRLF.
    if (layout.format != "ascii" && text.compare(after, 1, "\n") != 0)
        fail(line + 1, "a binary body's end_header line must end with a bare LF");
    layout.body_line = line + 2;
    return layout;
}

// A face's vertex index and texture coordinate lists: assimp 5.2 reads a texcoord list of six
// to eight items as two per vertex index, past the face's indices when it has fewer than four.
struct FaceLists {
    uint64_t indices = 0, texcoords = 0, texcoords_at = 0;
    void add(const PlyProperty& p, uint64_t count, uint64_t at) {
        if (p.name == "vertex_indices" || p.name == "vertex_index") indices = count;
        if (p.name == "texcoord") texcoords = count, texcoords_at = at;
    }
    template <class Fail>
    void check(Fail& fail) const {
        if (texcoords > 2 * indices)
            fail(texcoords_at, "a face's texcoord list of " + std::to_string(texcoords) +
                                   " items, more than two for each of its " +
                                   std::to_string(indices) + " vertex indices");
    }
};

// assimp 5.2 sizes its arrays from the counts a PLY file states (each element's count, each
// list's count) before reading what follows: a count of billions in a small file takes
// gigabytes (found by fuzzing: regressions/mesh_ply/). The body is walked as the header lays it
// out, and every count must fit in what is left of the file.
void check_ply_body(const std::string& text, const PlyLayout& layout) {
    const std::string where = layout.format == "ascii" ? "line " : "byte ";
    auto fail = [&](uint64_t at, const std::string& what) {
        throw std::runtime_error(where + std::to_string(at) + ": " + what);
    };
    for (const PlyElement& e : layout.elements)
        if (e.properties.empty() && e.count > text.size() - layout.body)
            fail(layout.format == "ascii" ? uint64_t(layout.body_line) : layout.body,
                 "element '" + e.name + "' states " + std::to_string(e.count) +
                     " instances without properties; more than the file could hold");
    if (layout.format == "ascii") {
        // assimp 5.2 reads an ASCII body a line per instance (a NUL, a form feed or a lone
        // carriage return also ends its lines, and it then drops the rest of the line): the
        // body may hold printable text, tabs and line ends only, and each instance is checked
        // on its own line, where a list must find its items.
        int line = layout.body_line;
        for (size_t i = layout.body; i < text.size(); ++i) {
            const unsigned char c = static_cast<unsigned char>(text[i]);
            if (c == '\n') ++line;
            const bool crlf = c == '\r' && i + 1 < text.size() && text[i + 1] == '\n';
            if ((c < 0x20 && c != '\n' && c != '\t' && !crlf) || c == 0x7f)
                fail(uint64_t(line), "a control character in the body");
        }
        std::istringstream in(text.substr(layout.body));
        line = layout.body_line - 1;
        std::string row;
        for (const PlyElement& e : layout.elements) {
            for (uint64_t i = 0; i < e.count; ++i) {
                if (!std::getline(in, row))
                    fail(uint64_t(line), "the body ends before instance " + std::to_string(i) +
                                             " of the " + std::to_string(e.count) + " '" + e.name +
                                             "' elements");
                ++line;
                std::istringstream words(row);
                std::vector<std::string> tokens;
                for (std::string w; words >> w;) tokens.push_back(w);
                size_t next = 0;
                FaceLists face;
                for (const PlyProperty& p : e.properties) {
                    if (next >= tokens.size())
                        fail(uint64_t(line), "too few numbers for instance " + std::to_string(i) +
                                                 " of the '" + e.name + "' elements");
                    if (!p.list) {
                        ++next;
                        continue;
                    }
                    const std::string& count = tokens[next++];
                    const bool digits = count.size() <= 10 &&
                                        count.find_first_not_of("0123456789") == std::string::npos;
                    const uint64_t items = digits ? std::stoull(count) : 0;
                    if (!digits || items > ply_count_max(p.count_type))
                        fail(uint64_t(line),
                             "'" + count + "' is not a list length of type " + p.count_type);
                    if (items > tokens.size() - next)
                        fail(uint64_t(line),
                             "a list of " + count + " items, more than its line holds");
                    face.add(p, items, uint64_t(line));
                    next += items;
                }
                if (e.name == "face") face.check(fail);
            }
        }
        return;
    }
    const bool big_endian = layout.format == "binary_big_endian";
    size_t at = layout.body;
    for (const PlyElement& e : layout.elements) {
        for (uint64_t i = 0; i < e.count; ++i) {
            FaceLists face;
            for (const PlyProperty& p : e.properties) {
                const size_t size = ply_type_size(p.list ? p.count_type : p.value_type);
                if (size > text.size() - at)
                    fail(at, "the body ends in instance " + std::to_string(i) + " of the " +
                                 std::to_string(e.count) + " '" + e.name + "' elements");
                if (!p.list) {
                    at += size;
                    continue;
                }
                uint64_t count = 0;
                for (size_t b = 0; b < size; ++b) {
                    const size_t byte = big_endian ? at + b : at + size - 1 - b;
                    count = count << 8 | static_cast<unsigned char>(text[byte]);
                }
                // A negative count in a signed type reads as a huge one here, and is refused.
                if (count > ply_count_max(p.count_type) ||
                    count > (text.size() - at - size) / ply_type_size(p.value_type))
                    fail(at, "a list of " + std::to_string(count) +
                                 " items, more than the file has left");
                face.add(p, count, at);
                at += size + count * ply_type_size(p.value_type);
            }
            if (e.name == "face") face.check(fail);
        }
    }
}

// assimp's number reader takes "1.#INF" (an old C library's infinity) as 1 and "0x1p200" as 0:
// in the text formats, every coordinate must be a finite decimal number before assimp reads it.
// OBJ: every number of a `v` line; ASCII PLY: every token after the header.
void check_text_formats(const std::string& path, std::vector<std::string>& warnings) {
    std::string ext = std::filesystem::path(path).extension().string();
    for (char& c : ext) c = char(std::tolower(static_cast<unsigned char>(c)));
    const std::string text = read_input_file(path, "mesh");
    const bool obj = ext == ".obj";
    if (ext == ".ply" || text.compare(0, 4, "ply\n") == 0 || text.compare(0, 5, "ply\r\n") == 0)
        check_ply_body(text, check_ply_header(text, &warnings));
    const bool ascii_ply =
        text.compare(0, 3, "ply") == 0 && text.find("format ascii") < text.find("end_header");
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
    TriangleMesh mesh;
    check_text_formats(path, mesh.warnings);
    Assimp::Importer importer;
    // Points and lines are removed rather than kept as degenerate triangles; vertices are
    // joined so that shared edges stay watertight for the triangle test.
    importer.SetPropertyInteger(AI_CONFIG_PP_SBP_REMOVE,
                                aiPrimitiveType_POINT | aiPrimitiveType_LINE);
    // Read first, check, then post-process: Debian's assimp keeps its assertions, and its
    // post-processing steps abort the process on a face without indices or an index past the
    // vertices (which a PLY file can hold). Its own validation step does not catch the first.
    const aiScene* raw = importer.ReadFile(path, 0);
    if (!raw || (raw->mFlags & AI_SCENE_FLAGS_INCOMPLETE))
        throw std::runtime_error(std::string("cannot import: ") + importer.GetErrorString());
    for (unsigned m = 0; m < raw->mNumMeshes; ++m) {
        const aiMesh* am = raw->mMeshes[m];
        for (unsigned f = 0; f < am->mNumFaces; ++f) {
            const aiFace& face = am->mFaces[f];
            if (face.mNumIndices == 0 || !face.mIndices)
                throw std::runtime_error("face " + std::to_string(f) + " has no vertices");
            for (unsigned k = 0; k < face.mNumIndices; ++k)
                if (face.mIndices[k] >= am->mNumVertices)
                    throw std::runtime_error("face " + std::to_string(f) + " names vertex " +
                                             std::to_string(face.mIndices[k]) + " of " +
                                             std::to_string(am->mNumVertices));
        }
    }
    const aiScene* scene =
        importer.ApplyPostProcessing(aiProcess_Triangulate | aiProcess_JoinIdenticalVertices |
                                     aiProcess_PreTransformVertices | aiProcess_SortByPType);
    if (!scene)
        throw std::runtime_error(std::string("cannot import: ") + importer.GetErrorString());
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
