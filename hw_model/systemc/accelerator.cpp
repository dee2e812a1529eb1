#include "hw_model/systemc/accelerator.h"

namespace sfx {

Accelerator::Accelerator(sc_core::sc_module_name name, const HwConfig& c, const WorkloadShape& shape,
                         std::shared_ptr<SharedSceneMemory> scene_memory)
    : sc_module(name) {
    const RayRecordLayout layout(shape.features);
    const uint32_t capacity = uint32_t(uint64_t(c.ray_buffer.kib) * 1024 / layout.bytes());
    m_ray_buffer = std::make_unique<RayBufferUnit>("ray_buffer", c.ray_buffer, layout.words(),
                                                   std::max(capacity, shape.slots()));
    m_address = std::make_unique<AddressUnit>("agu", c.agu);
    m_simd = std::make_unique<SimdUnit>("simd", shape.needed_kinds());
    m_partition = std::make_unique<PartitionUnit>("partition", c.partition, c.simd.width);
    m_scratchpad = std::make_unique<ScratchpadUnit>("scratchpad", c.scratchpad);
    m_interconnect = std::make_unique<InterconnectUnit>("interconnect", c.interconnect, c.clock);
    m_scene_memory = std::make_unique<SceneMemoryUnit>("scene_memory", std::move(scene_memory));
    SceneDataMap map;
    map.nodes = shape.bvh_nodes;
    map.triangles = shape.triangles;
    map.spheres = shape.spheres;
    m_sequencer = std::make_unique<Sequencer>("sequencer", OpCostTable(layout, c.datapath), map,
                                              c.simd.width, c.clock.core_mhz);
    m_sequencer->ray_buffer(*m_ray_buffer);
    m_sequencer->address(*m_address);
    m_sequencer->simd(*m_simd);
    m_sequencer->partition(*m_partition);
    m_sequencer->scratchpad(*m_scratchpad);
    m_sequencer->interconnect(*m_interconnect);
    m_sequencer->scene_memory(*m_scene_memory);
}

FrameTiming Accelerator::timing() const {
    FrameTiming t = m_sequencer->timing();
    const SceneMemoryModel& memory = m_scene_memory->model();
    t.cache_hits.clear();
    t.cache_misses.clear();
    for (const SetAssociativeCache& level : memory.levels()) {
        t.cache_hits.push_back(level.hits());
        t.cache_misses.push_back(level.misses());
    }
    t.dram_reads = memory.dram_reads();
    return t;
}

}  // namespace sfx
