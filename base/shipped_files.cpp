#include "base/shipped_files.h"

#include <algorithm>
#include <cstdlib>

namespace sfx {

std::filesystem::path shipped_dir(const char* env_var, const char* compiled_default) {
    if (const char* env = std::getenv(env_var); env && *env) return env;
    return compiled_default;
}

bool is_shipped_name(const std::string& name) {
    return !name.empty() && name.find('/') == std::string::npos &&
           name.find(".yaml") == std::string::npos;
}

std::vector<std::string> shipped_names(const std::filesystem::path& dir, const std::string& suffix) {
    std::vector<std::string> names;
    std::error_code ec;
    for (std::filesystem::directory_iterator it(dir, ec), end; !ec && it != end; it.increment(ec)) {
        const std::string file = it->path().filename().string();
        if (file.size() > suffix.size() &&
            file.compare(file.size() - suffix.size(), suffix.size(), suffix) == 0)
            names.push_back(file.substr(0, file.size() - suffix.size()));
    }
    std::sort(names.begin(), names.end());
    return names;
}

}  // namespace sfx
