#include "hw_model/tech_table.h"

#include <filesystem>
#include <map>
#include <memory>
#include <mutex>

#include "base/strict_yaml.h"
#include "base/user_files.h"
#include "hw_model/tech/builtin_tech.h"  // generated: k_builtin_tech[] = {name, yaml text}

namespace sfx {
namespace {

// Every dotted key a table must contain (a table has no defaults: no number goes unsourced).
class KeyLister {
  public:
    explicit KeyLister(std::vector<std::string>& out, std::string prefix = "")
        : m_out(out), m_prefix(std::move(prefix)) {}
    template <class T, class B>
    void param(const char* name, T&, const char*, const char*, B, B) {
        m_out.push_back(strict_yaml::join(m_prefix, name));
    }
    template <class T>
    void param(const char* name, T&, const char*, const char*) {
        m_out.push_back(strict_yaml::join(m_prefix, name));
    }
    template <class G>
    void group(const char* name, G& g) {
        KeyLister l(m_out, strict_yaml::join(m_prefix, name));
        g.visit(l);
    }

  private:
    std::vector<std::string>& m_out;
    std::string m_prefix;
};

}  // namespace

TechTable parse_tech_table(const std::string& text, const std::string& file) {
    YAML::Node root;
    try {
        root = YAML::Load(text);
    } catch (const YAML::Exception& e) {
        throw InputError(file, e.mark.line >= 0 ? e.mark.line + 1 : 0, "", e.msg);
    }
    TechTable table;
    std::map<std::string, int> lines;
    strict_yaml::YamlReader reader(root, file, "", lines);
    table.visit(reader);
    reader.finish();
    std::vector<std::string> keys;
    KeyLister lister(keys);
    table.visit(lister);
    for (const std::string& key : keys)
        if (!lines.count(key)) {
            // The line of the enclosing group, when it was written.
            const auto dot = key.find('.');
            const auto group =
                dot == std::string::npos ? lines.end() : lines.find(key.substr(0, dot));
            throw InputError(file, group == lines.end() ? 0 : group->second, key,
                             "missing (every number of a technology table is required)");
        }
    if (table.name.empty()) throw InputError(file, lines["name"], "name", "must not be empty");
    return table;
}

TechTable load_tech_table(const std::string& path) {
    return parse_tech_table(read_input_file(path, "technology table"), path);
}

std::vector<std::string> builtin_tech_names() {
    std::vector<std::string> names;
    for (const BuiltinTech& t : k_builtin_tech) names.push_back(t.name);
    return names;
}

std::string unknown_tech_reason(const std::string& name_or_path) {
    for (const BuiltinTech& t : k_builtin_tech)
        if (name_or_path == t.name) return "";
    std::error_code ec;
    if (std::filesystem::is_regular_file(name_or_path, ec)) return "";
    std::string names;
    for (const BuiltinTech& t : k_builtin_tech)
        names += names.empty() ? t.name : std::string(", ") + t.name;
    return "'" + name_or_path + "' is neither a built-in technology (" + names +
           ") nor a readable *.tech.yaml file";
}

TechTable resolve_tech_table(const std::string& name_or_path, const std::string& key,
                             const std::string& file, int line) {
    for (const BuiltinTech& t : k_builtin_tech)
        if (name_or_path == t.name)
            return parse_tech_table(t.yaml, std::string(t.name) + ".tech.yaml");
    const std::string unknown = unknown_tech_reason(name_or_path);
    if (!unknown.empty()) throw InputError(file, line, key, unknown);
    return load_tech_table(name_or_path);
}

const TechTable& tech_table_for(const std::string& name_or_path, const std::string& key,
                                const std::string& file, int line) {
    static std::mutex mutex;
    static std::map<std::string, std::unique_ptr<const TechTable>> tables;
    const std::lock_guard<std::mutex> lock(mutex);
    auto it = tables.find(name_or_path);
    if (it == tables.end())
        it = tables
                 .emplace(name_or_path, std::make_unique<const TechTable>(
                                            resolve_tech_table(name_or_path, key, file, line)))
                 .first;
    return *it->second;
}

const TechTable& default_tech_table() {
    return tech_table_for("90nm");
}

}  // namespace sfx
