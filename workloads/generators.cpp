#include "workloads/generators.h"

#include "workloads/generator_kit.h"

namespace sfx {

// The registry, in a stable order: one entry per generator_<name>.cpp.
const std::vector<GeneratorInfo>& generators() {
    static const std::vector<GeneratorInfo> list = {atrium_generator(), conference_generator(),
                                                    temple_generator()};
    return list;
}

const GeneratorInfo* find_generator(const std::string& name) {
    for (const GeneratorInfo& g : generators())
        if (g.name == name) return &g;
    return nullptr;
}

}  // namespace sfx
