#pragma once
// What each kind of stream operation asks of the hardware: which ray-record words it gathers
// for every lane, which it scatters for the lanes that pass, how many SIMD compute instructions
// it issues per lane group, which datapath latency it pays, what scene data it fetches, and
// whether its mask partitions the stream. Counting lives here; costing (cycles) lives in the
// models that read this table, so the analytic and cycle-level models cannot disagree about
// the work, only about its price.

#include <array>
#include <cstdint>
#include <string>
#include <vector>

#include "hw_model/hw_config.h"
#include "kernels/trace.h"
#include "workloads/scene.h"

namespace sfx {

// Word offsets of the ray-record fields (structure of arrays: field word w of slot s is at
// w * capacity + s). Fields a scene does not need are absent (offset -1).
class RayRecordLayout {
  public:
    explicit RayRecordLayout(const FeatureSet& features);
    uint32_t words() const { return m_words; }
    uint32_t bytes() const { return m_words * 4; }
    // Word offsets of a named field (empty when the scene has no such field).
    const std::vector<uint32_t>& field(const std::string& name) const;

  private:
    uint32_t m_words = 0;
    std::vector<std::pair<std::string, std::vector<uint32_t>>> m_fields;
    std::vector<uint32_t> m_none;
};

struct OpProfile {
    std::vector<uint32_t> gather_words;   // gathered for every lane
    std::vector<uint32_t> scatter_words;  // scattered for passing lanes
    uint32_t compute_instructions = 1;    // SIMD instructions per lane group
    uint32_t chain_steps = 1;             // longest dependent chain of those instructions
    uint32_t latency_cycles = 1;          // chain_steps * fp latency: paid once per group
    uint32_t scene_bytes = 0;             // scene data fetched once per op (broadcast operand)
    bool partitions = false;              // the mask partitions the stream in place (op table)
    bool pushes_rays = false;             // passing lanes write the next generation (op table)
};

// One profile per OpKind for a scene's layout and a configuration's datapath.
class OpCostTable {
  public:
    OpCostTable(const RayRecordLayout& layout, const DatapathConfig& datapath);
    const OpProfile& operator[](OpKind kind) const { return m_profiles[size_t(kind)]; }

  private:
    std::array<OpProfile, k_op_kind_count> m_profiles;
};

// Where the scene data of an op's object lives (a flat layout: nodes, then triangles' vertex
// triples, then spheres, then materials), for the cache model.
struct SceneDataMap {
    uint64_t node_bytes = 32, triangle_bytes = 36, sphere_bytes = 16, material_bytes = 64;
    uint64_t nodes = 0, triangles = 0, spheres = 0;

    uint64_t address(OpKind kind, uint32_t object) const;
};

}  // namespace sfx
