#pragma once
// Loading scenes: `*.scene.yaml` files (strict: unknown keys are InputErrors naming file, line
// and dotted path), meshes through assimp, and the procedural generators they may call.

#include <string>
#include <vector>

#include "workloads/scene.h"

namespace sfx {

// `name_or_path` is a file path, or the name of a shipped scene in workloads/scenes
// ("cornell" finds workloads/scenes/cornell.scene.yaml). Throws InputError on bad input.
Scene load_scene(const std::string& name_or_path);

// Names of the shipped scenes, in a stable order.
std::vector<std::string> builtin_scene_names();

}  // namespace sfx
