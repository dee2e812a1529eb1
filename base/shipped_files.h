#pragma once
// Files shipped with sfx and found by name (scenes: `sfx render cornell`; hardware presets:
// `sfx simulate gr08`): where they live and which names there are, one way for every kind.

#include <filesystem>
#include <string>
#include <vector>

namespace sfx {

// The directory of one kind of shipped file: the environment variable `env_var` when it is
// set and not empty (an installed or relocated tree), else `compiled_default`, the source
// tree's folder given at build time.
std::filesystem::path shipped_dir(const char* env_var, const char* compiled_default);

// Whether `name` is meant as a shipped file's name rather than a path: not empty, no '/', no
// ".yaml" in it.
bool is_shipped_name(const std::string& name);

// The names of the files `dir/NAME<suffix>` (e.g. ".scene.yaml"), sorted; none if `dir` cannot
// be read.
std::vector<std::string> shipped_names(const std::filesystem::path& dir, const std::string& suffix);

}  // namespace sfx
