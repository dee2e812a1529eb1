#include "tests/fuzz/fuzz_targets.h"

#include <unistd.h>

#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <stdexcept>
#include <string>

#include "hw_model/hw_config.h"
#include "kernels/trace.h"
#include "sweeps/results_store.h"
#include "sweeps/explore.h"
#include "sweeps/sweep.h"
#include "base/input_error.h"
#include "workloads/mesh_import.h"
#include "workloads/scene_loader.h"

namespace sfx::fuzz {
namespace {

[[noreturn]] void bug(const std::string& what) {
    std::fprintf(stderr, "fuzz: %s\n", what.c_str());
    std::fflush(stderr);
    std::abort();
}

// One directory per process for the files the parsers must read from a path. In memory
// (/dev/shm) where there is one: rewriting a file on ext4 flushes it to disk on every
// execution, which made the file-reading targets spend most of their time in the kernel.
const std::filesystem::path& work_dir() {
    static const std::filesystem::path dir = [] {
        std::error_code ec;
        const std::filesystem::path base =
            std::filesystem::is_directory("/dev/shm", ec) && ::access("/dev/shm", W_OK) == 0
                ? std::filesystem::path("/dev/shm")
                : std::filesystem::temp_directory_path();
        std::string templ = (base / "sfx-fuzz-XXXXXX").string();
        if (!::mkdtemp(templ.data())) bug("mkdtemp failed");
        std::atexit([] {
            std::error_code ec;
            std::filesystem::remove_all(work_dir(), ec);
        });
        return std::filesystem::path(templ);
    }();
    return dir;
}

std::string write_input(const std::string& name, const uint8_t* data, size_t size) {
    const std::string path = (work_dir() / name).string();
    std::ofstream out(path, std::ios::binary | std::ios::trunc);
    out.write(reinterpret_cast<const char*>(data), std::streamsize(size));
    if (!out) bug("cannot write " + path);
    return path;
}

bool finite(const Vec3& v) {
    return std::isfinite(v.x) && std::isfinite(v.y) && std::isfinite(v.z);
}

// The scene invariants every consumer relies on.
void check_scene(const Scene& s) {
    for (const Vec3& p : s.positions)
        if (!finite(p)) bug("a loaded scene has a non-finite vertex");
    for (const Triangle& t : s.triangles)
        if (t.v0 >= s.positions.size() || t.v1 >= s.positions.size() ||
            t.v2 >= s.positions.size() || t.material >= s.materials.size())
            bug("a loaded scene has a triangle indexing past its arrays");
    for (const Sphere& sp : s.spheres)
        if (!finite(sp.center) || !std::isfinite(sp.radius) || !(sp.radius > 0.f) ||
            sp.material >= s.materials.size())
            bug("a loaded scene has a bad sphere");
    for (const AreaLight& l : s.lights)
        for (uint32_t p : l.primitives)
            if (p >= s.primitive_count()) bug("a light names a primitive past the scene");
    if (!finite(s.camera.eye)) bug("a loaded scene has a non-finite camera");
}

// Checks what the trace format promises a sink: ops inside a pass, slots inside the pass.
class CheckingSink : public TraceSink {
  public:
    void begin_pass(const TilePass& p) override {
        m_pass = p;
        m_in_pass = true;
    }
    void op(const StreamOp& op) override {
        if (!m_in_pass) bug("trace reader delivered an op outside a pass");
        if (op.length > m_pass.slot_count) bug("trace reader delivered an op longer than its pass");
        uint32_t passed = 0;
        for (uint32_t i = 0; i < op.length; ++i) {
            if (op.slots[i] >= m_pass.slot_count)
                bug("trace reader delivered a slot past the pass");
            passed += op.passed[i];
        }
        if (passed != op.pass_count) bug("trace reader delivered a wrong pass count");
    }
    void end_pass(const TilePass&) override { m_in_pass = false; }

  private:
    TilePass m_pass;
    bool m_in_pass = false;
};

}  // namespace

void hw_config(const uint8_t* data, size_t size) {
    const std::string text(reinterpret_cast<const char*>(data), size);
    HwConfig config;
    try {
        config = parse_hw_config(text, "fuzz.hw.yaml");
    } catch (const InputError&) {
        return;
    }
    const std::string first = dump_hw_config(config);
    std::string second;
    try {
        second = dump_hw_config(parse_hw_config(first, "dump.hw.yaml"));
    } catch (const InputError& e) {
        bug(std::string("the dump of an accepted config does not parse: ") + e.what() + "\n" +
            first);
    }
    if (first != second)
        bug("dump -> parse -> dump changed the text:\n" + first + "---\n" + second);
}

void scene(const uint8_t* data, size_t size) {
    const std::string path = write_input("fuzz.scene.yaml", data, size);
    try {
        check_scene(load_scene(path));
    } catch (const InputError&) {
    }
}

void sweep(const uint8_t* data, size_t size) {
    const std::string text(reinterpret_cast<const char*>(data), size);
    try {
        // A small guard: the fuzzer would otherwise spend its runs expanding 10^6-point sweeps.
        const Sweep s = parse_sweep(text, "fuzz.sweep.yaml", SFX_SOURCE_DIR "/sweeps", {}, 10000);
        size_t grouped = 0;
        for (const PointGroup& g : s.groups) grouped += g.points.size();
        if (grouped != s.point_count) bug("sweep groups do not hold every point once");
        // Points are made on demand: the first and last of a group must be made and keyed.
        for (size_t g = 0; g < s.groups.size() && g < 4; ++g) {
            if (s.point(s.groups[g].points.front()).key.empty()) bug("a point without a key");
            if (s.point(s.groups[g].points.back()).workload != s.groups[g].workload)
                bug("a point outside its group's workload");
        }
    } catch (const InputError&) {
    }
}

void explore(const uint8_t* data, size_t size) {
    const std::string text(reinterpret_cast<const char*>(data), size);
    try {
        const ExploreSpec e = parse_explore(text, "fuzz.yaml", SFX_SOURCE_DIR "/sweeps", {}, 10000);
        const size_t n = e.configurations();
        if (n == 0 || e.budget_evaluations == 0 || e.budget_evaluations > n) bug("an explore's budget outside its space");
        for (size_t c : {size_t(0), n / 2, n - 1}) {
            if (e.config_of(e.knob_positions(c)) != c) bug("a configuration's knob positions do not round-trip");
            for (size_t w = 0; w < e.workloads.size() && w < 2; ++w)
                if (e.point(w, c, e.confirm).key.empty()) bug("an explore point without a key");
        }
    } catch (const InputError&) {
    }
}

namespace {
// import_mesh reports assimp's refusals as std::runtime_error (mesh_import.h); the scene
// loader turns them into InputErrors. An accepted mesh must be finite and indexed in range.
void mesh(const std::string& name, const uint8_t* data, size_t size) {
    const std::string path = write_input(name, data, size);
    TriangleMesh m;
    try {
        m = import_mesh(path);
    } catch (const std::runtime_error&) {
        return;
    }
    for (const Vec3& p : m.positions)
        if (!finite(p)) bug("an imported mesh has a non-finite vertex");
    if (m.indices.size() % 3 != 0) bug("an imported mesh has a partial triangle");
    for (uint32_t i : m.indices)
        if (i >= m.positions.size()) bug("an imported mesh indexes past its vertices");
}
}  // namespace

void mesh_obj(const uint8_t* data, size_t size) {
    mesh("fuzz.obj", data, size);
}
void mesh_ply(const uint8_t* data, size_t size) {
    mesh("fuzz.ply", data, size);
}

void store(const uint8_t* data, size_t size) {
    const std::string path = write_input("fuzz.db", data, size);
    for (const char* suffix : {"-wal", "-shm", "-journal"}) std::remove((path + suffix).c_str());
    for (auto access : {ResultsStore::Access::read_only, ResultsStore::Access::read_write}) {
        try {
            ResultsStore s(path, access);
            // A store that opened may still be damaged further in: SQLite finds that on the read
            // that reaches the bad page, and the store reports it as "results store: ...".
            try {
                for (const std::string& key : s.keys()) s.numbers(key);
                s.rows();
                s.export_csv((work_dir() / "fuzz.csv").string());
            } catch (const InputError&) {
            } catch (const std::runtime_error& e) {
                if (std::string(e.what()).rfind("results store", 0) != 0) throw;
            }
        } catch (const InputError&) {
        }
    }
}

void trace(const uint8_t* data, size_t size) {
    const std::string path = write_input("fuzz.trc", data, size);
    CheckingSink sink;
    try {
        read_trace_file(path, sink);
    } catch (const InputError&) {
    }
}

const std::vector<TargetInfo>& targets() {
    static const std::vector<TargetInfo> list = {
        {"hw_config", hw_config}, {"scene", scene}, {"sweep", sweep}, {"explore", explore}, {"mesh_obj", mesh_obj},
        {"mesh_ply", mesh_ply},   {"store", store}, {"trace", trace},
    };
    return list;
}

}  // namespace sfx::fuzz
