#include "hw_model/hw_config.h"

#include "base/strict_yaml.h"

#include <yaml-cpp/yaml.h>

#include <cerrno>
#include <algorithm>
#include <cmath>
#include <filesystem>
#include <cstdlib>
#include <fstream>
#include <map>
#include <set>
#include <string_view>
#include <sstream>

#include "kernels/trace.h"
#include "hw_model/tech_table.h"
#include "base/input_error.h"
#include "base/shipped_files.h"
#include "base/user_files.h"
#include "base/strict_number.h"

#ifndef SFX_PRESET_DIR
#define SFX_PRESET_DIR "hw_model/presets"
#endif

namespace sfx {
namespace {

using namespace strict_yaml;

class YamlWriter {
public:
    explicit YamlWriter(YAML::Emitter& out) : m_out(out) {}
    template <class T, class B> void param(const char* name, T& value, const char* unit,
                                           const char* description, B, B) {
        param(name, value, unit, description);
    }
    template <class T> void param(const char* name, T& value, const char* unit, const char* description) {
        m_out << YAML::Key << name << YAML::Value;
        write(value);
        std::string comment = description;
        if (*unit) comment += std::string(" [") + unit + "]";
        m_out << YAML::Comment(comment);
    }
    void choice(const char* name, std::string& value, std::initializer_list<const char*>,
                const char* description) {
        param(name, value, "", description);
    }
    template <class G> void group(const char* name, G& g) {
        m_out << YAML::Key << name << YAML::Value << YAML::BeginMap;
        g.visit(*this);
        m_out << YAML::EndMap;
    }
    template <class G> void list(const char* name, std::vector<G>& items, const char*) {
        m_out << YAML::Key << name << YAML::Value << YAML::BeginSeq;
        for (G& item : items) {
            m_out << YAML::BeginMap;
            item.visit(*this);
            m_out << YAML::EndMap;
        }
        m_out << YAML::EndSeq;
    }

private:
    void write(uint32_t v) { m_out << v; }
    void write(bool v) { m_out << (v ? "true" : "false"); }
    void write(const std::string& v) { m_out << YAML::DoubleQuoted << v; }
    void write(double v) { m_out << to_text(v); }
    YAML::Emitter& m_out;
};

// Values only, as block YAML at a given indent, written directly: a sweep writes one per point.
// Strings are double-quoted, numbers as to_text writes them; parse_hw_config reads it back.
class ValuesWriter {
public:
    ValuesWriter(std::string& out, size_t indent) : m_out(out), m_indent(indent) {}
    template <class T, class B> void param(const char* name, T& value, const char* unit,
                                           const char* description, B, B) {
        param(name, value, unit, description);
    }
    template <class T> void param(const char* name, T& value, const char*, const char*) {
        key(name);
        m_out += ' ';
        m_out += text(value);
        m_out += '\n';
    }
    void choice(const char* name, std::string& value, std::initializer_list<const char*>,
                const char*) {
        param(name, value, "", "");
    }
    template <class G> void group(const char* name, G& g) {
        key(name);
        m_out += '\n';
        ValuesWriter inner(m_out, m_indent + 2);
        g.visit(inner);
    }
    template <class G> void list(const char* name, std::vector<G>& items, const char*) {
        key(name);
        if (items.empty()) {
            m_out += " []\n";
            return;
        }
        m_out += '\n';
        for (G& item : items) {
            // "- " takes the place of the item's first two columns of indent.
            const size_t start = m_out.size();
            ValuesWriter inner(m_out, m_indent + 4);
            item.visit(inner);
            m_out[start + m_indent + 2] = '-';
        }
    }

private:
    void key(const char* name) {
        m_out.append(m_indent, ' ');
        m_out += name;
        m_out += ':';
    }
    static std::string text(const std::string& v) { return double_quoted(v); }
    template <class T> static std::string text(const T& v) { return to_text(v); }
    std::string& m_out;
    size_t m_indent;
};

class Flattener {
public:
    explicit Flattener(std::vector<HwParamInfo>& out, std::string prefix = "")
        : m_out(out), m_prefix(std::move(prefix)) {}
    template <class T, class B> void param(const char* name, T& value, const char* unit,
                                           const char* description, B, B) {
        param(name, value, unit, description);
    }
    template <class T> void param(const char* name, T& value, const char* unit, const char* description) {
        m_out.push_back({join(m_prefix, name), to_text(value), unit, description});
    }
    void choice(const char* name, std::string& value, std::initializer_list<const char*>,
                const char* description) {
        param(name, value, "", description);
    }
    template <class G> void group(const char* name, G& g) {
        Flattener f(m_out, join(m_prefix, name));
        g.visit(f);
    }
    template <class G> void list(const char* name, std::vector<G>& items, const char*) {
        for (size_t i = 0; i < items.size(); ++i) {
            Flattener f(m_out, join(m_prefix, name) + "[" + std::to_string(i) + "]");
            items[i].visit(f);
        }
    }

private:
    std::vector<HwParamInfo>& m_out;
    std::string m_prefix;
};

// Finds one parameter by dotted path and assigns it through the same range checks as YAML.
class Setter {
public:
    Setter(const std::string& target, const std::string& value, const std::string& file, int line,
           std::string prefix = "")
        : m_target(target), m_value(value), m_file(file), m_line(line), m_prefix(std::move(prefix)) {}
    bool found() const { return m_found; }

    template <class T, class B> void param(const char* name, T& value, const char*, const char*,
                                           B lo, B hi) {
        if (!assign(name, value)) return;
        if (!in_range(value, T(lo), T(hi)))
            throw InputError(m_file, m_line, m_target,
                             "value " + m_value + " is outside [" + to_text(T(lo)) + ", " +
                                 to_text(T(hi)) + "]");
    }
    template <class T> void param(const char* name, T& value, const char*, const char*) {
        assign(name, value);
    }
    void choice(const char* name, std::string& value, std::initializer_list<const char*> allowed,
                const char*) {
        if (!is_target(name)) return;
        for (const char* a : allowed)
            if (m_value == a) {
                value = m_value;
                m_found = true;
                return;
            }
        throw InputError(m_file, m_line, m_target, "'" + m_value + "' is not an allowed value");
    }
    // Groups and lists off the target's path are not entered: a sweep sets parameters at
    // every point, so this walk is on its hot path.
    template <class G> void group(const char* name, G& g) {
        if (!leads_to_target(name, '.')) return;
        Setter s(m_target, m_value, m_file, m_line, join(m_prefix, name));
        g.visit(s);
        m_found |= s.m_found;
    }
    template <class G> void list(const char* name, std::vector<G>& items, const char*) {
        if (!leads_to_target(name, '[')) return;
        for (size_t i = 0; i < items.size(); ++i) {
            Setter s(m_target, m_value, m_file, m_line,
                     join(m_prefix, name) + "[" + std::to_string(i) + "]");
            items[i].visit(s);
            m_found |= s.m_found;
        }
    }

private:
    // The rest of the target below this setter's prefix (empty if the target is not below it).
    std::string_view below_prefix() const {
        std::string_view t(m_target);
        if (m_prefix.empty()) return t;
        if (t.size() <= m_prefix.size() || t.compare(0, m_prefix.size(), m_prefix) != 0 ||
            t[m_prefix.size()] != '.')
            return {};
        return t.substr(m_prefix.size() + 1);
    }
    // join(m_prefix, name) == m_target, without building the string.
    bool is_target(const char* name) const { return below_prefix() == name; }
    // The target is inside `name`: it continues with `next` ('.' or '[') after the name.
    bool leads_to_target(const char* name, char next) const {
        const std::string_view rest = below_prefix();
        const size_t n = std::char_traits<char>::length(name);
        return rest.size() > n && rest.compare(0, n, name) == 0 && rest[n] == next;
    }

    template <class T> bool assign(const char* name, T& value) {
        if (!is_target(name)) return false;
        T parsed{};
        if (!parse_scalar(m_value, parsed))
            throw InputError(m_file, m_line, m_target, std::string("expected ") + type_name(parsed));
        value = parsed;
        m_found = true;
        return true;
    }
    const std::string& m_target;
    const std::string& m_value;
    const std::string& m_file;
    int m_line;
    std::string m_prefix;
    bool m_found = false;
};

bool is_power_of_two(uint32_t v) { return v && !(v & (v - 1)); }

}  // namespace

void check_hw_config(const HwConfig& c, const std::string& file, const HwLineMap& lines) {
    auto fail = [&](const std::string& key, const std::string& what) {
        // The line of the key itself, else of the nearest enclosing key that was written.
        for (std::string k = key;; k = k.substr(0, k.find_last_of(".["))) {
            auto it = lines.find(k);
            if (it != lines.end()) throw InputError(file, it->second, key, what);
            if (k.find_first_of(".[") == std::string::npos) break;
        }
        throw InputError(file, 0, key, what);
    };
    if (c.ray_buffer.kib % c.ray_buffer.banks != 0)
        fail("ray_buffer.banks", std::to_string(c.ray_buffer.banks) + " banks do not divide " +
                                     std::to_string(c.ray_buffer.kib) + " KiB");
    if ((uint64_t(c.ray_buffer.bank_kib()) * 1024) % (4ull * c.ray_buffer.line_words) != 0)
        fail("ray_buffer.line_words", "a bank does not hold a whole number of lines");
    if (c.scene_memory.caches.size() > 8) fail("scene_memory.caches", "at most 8 cache levels");
    std::set<std::string> names;
    for (size_t i = 0; i < c.scene_memory.caches.size(); ++i) {
        const CacheLevelConfig& l = c.scene_memory.caches[i];
        const std::string key = "scene_memory.caches[" + std::to_string(i) + "]";
        if (!is_power_of_two(l.line_bytes)) fail(key + ".line_bytes", "must be a power of two");
        const uint64_t lines = uint64_t(l.kib) * 1024 / l.line_bytes;
        if (lines == 0 || lines % l.ways != 0 || (uint64_t(l.kib) * 1024) % l.line_bytes != 0)
            fail(key + ".ways", "capacity must be a whole number of sets of " +
                                    std::to_string(l.ways) + " lines");
        if (l.name.empty() || !names.insert(l.name).second)
            fail(key + ".name", "cache level names must be unique and non-empty");
    }
    const std::vector<DramSpanLatency>& spans = c.scene_memory.dram_latency_by_span;
    for (size_t i = 1; i < spans.size(); ++i)
        if (spans[i].span_mib <= spans[i - 1].span_mib)
            fail("scene_memory.dram_latency_by_span[" + std::to_string(i) + "].span_mib",
                 "spans must grow from one entry to the next");
    std::set<std::string> ops;
    for (size_t i = 0; i < c.op_costs.size(); ++i) {
        const std::string& op = c.op_costs[i].op;
        const std::string key = "op_costs[" + std::to_string(i) + "].op";
        if (op_kind_named(op) == OpKind::count)
            fail(key, "'" + op + "' is not an op kind (kernels/trace.h)");
        if (!ops.insert(op).second) fail(key, "'" + op + "' has two cost entries");
    }
    const std::string unknown = unknown_tech_reason(c.tech.node);
    if (!unknown.empty()) fail("tech.node", unknown);
    tech_table_for(c.tech.node);  // a table file's own errors name that file, line and key
}

HwConfig parse_hw_config(const std::string& text, const std::string& file) {
    return hw_config_from_yaml(parse_yaml_document(text, file), file);
}

HwConfig hw_config_from_yaml(const YAML::Node& root, const std::string& file) {
    HwConfig config;
    HwLineMap lines;
    YamlReader reader(root, file, "", lines);
    config.visit(reader);
    reader.finish();
    config.clock.core_written = lines.count("clock.core_mhz") > 0;
    config.clock.interconnect_written = lines.count("clock.interconnect_mhz") > 0;
    check_hw_config(config, file, lines);
    return config;
}

static std::filesystem::path preset_dir() { return shipped_dir("SFX_PRESET_DIR", SFX_PRESET_DIR); }

std::vector<std::string> builtin_preset_names() { return shipped_names(preset_dir(), ".hw.yaml"); }

HwConfig load_hw_config(const std::string& path) {
    if (path.empty())
        throw InputError("command line", 0, "", "a hardware configuration name is empty");
    // A plain name that is not a file is a shipped preset (hw_model/presets/NAME.hw.yaml), as
    // scene names are shipped scenes.
    std::error_code ec;
    if (is_shipped_name(path) && !std::filesystem::exists(path, ec)) {
        const std::filesystem::path preset = preset_dir() / (path + ".hw.yaml");
        if (!std::filesystem::is_regular_file(preset, ec)) {
            std::string list;
            for (const std::string& n : builtin_preset_names()) list += (list.empty() ? "" : ", ") + n;
            // Name the directory searched when it lists nothing: SFX_PRESET_DIR may be wrong.
            const char* env = std::getenv("SFX_PRESET_DIR");
            if (list.empty())
                list =
                    "none in " + preset_dir().string() + (env && *env ? " (SFX_PRESET_DIR)" : "");
            throw InputError(path, 0, "", "no such hardware configuration file or preset (presets: " +
                                              list + ")");
        }
        return parse_hw_config(read_input_file(preset.string(), "hardware configuration"),
                               preset.string());
    }
    return parse_hw_config(read_input_file(path, "hardware configuration"), path);
}

void check_machine_model_config(const HwConfig& config) {
    const bool l1d = config.ray_buffer.storage == "l1d";
    if (l1d && config.op_costs.empty())
        throw InputError(config.name, 0, "op_costs",
                         "ray_buffer.storage l1d needs measured op costs: the L1D's loads and "
                         "stores are priced inside them (write them with sfx calibrate "
                         "--describe-host)");
    if (!l1d && !config.op_costs.empty())
        throw InputError(config.name, 0, "op_costs",
                         "measured op costs include the lanes' loads and stores, so they need "
                         "ray_buffer.storage l1d (with banks the gathers would be priced twice)");
}

std::string dump_hw_config(const HwConfig& config) {
    YAML::Emitter out;
    out << YAML::BeginMap;
    YamlWriter writer(out);
    const_cast<HwConfig&>(config).visit(writer);  // the writer only reads
    out << YAML::EndMap;
    return std::string(out.c_str()) + "\n";
}

std::string hw_config_values_yaml(const HwConfig& config, size_t indent) {
    std::string out;
    ValuesWriter writer(out, indent);
    const_cast<HwConfig&>(config).visit(writer);  // the writer only reads
    return out;
}

std::vector<HwParamInfo> flatten_hw_config(const HwConfig& config) {
    std::vector<HwParamInfo> out;
    Flattener f(out);
    const_cast<HwConfig&>(config).visit(f);  // the flattener only reads
    return out;
}

std::vector<ConfigLabel> label_configs(const std::vector<HwConfig>& configs,
                                       const std::vector<std::string>& sources) {
    auto stem = [](const std::string& source) {
        std::string n = std::filesystem::path(source).filename().string();
        for (const std::string suffix : {".hw.yaml", ".yaml"})
            if (n.size() > suffix.size() && n.compare(n.size() - suffix.size(), suffix.size(), suffix) == 0) {
                n.resize(n.size() - suffix.size());
                break;
            }
        return n;
    };
    auto unique = [](const std::vector<std::string>& names, size_t i) {
        return std::count(names.begin(), names.end(), names[i]) == 1;
    };
    std::vector<std::string> names, stems;
    for (size_t i = 0; i < configs.size(); ++i) {
        names.push_back(configs[i].name);
        stems.push_back(i < sources.size() ? stem(sources[i]) : configs[i].name);
    }
    std::vector<ConfigLabel> out(configs.size());
    const std::vector<HwParamInfo> first = configs.empty() ? std::vector<HwParamInfo>{}
                                                           : flatten_hw_config(configs.front());
    for (size_t i = 0; i < configs.size(); ++i) {
        out[i].name = unique(names, i)   ? names[i]
                      : unique(stems, i) ? stems[i]
                                         : names[i] + " #" + std::to_string(i + 1);
        if (i == 0) continue;
        const std::vector<HwParamInfo> mine = flatten_hw_config(configs[i]);
        std::map<std::string, std::string> base;
        for (const HwParamInfo& p : first) base[p.path] = p.value;
        for (const HwParamInfo& p : mine) {
            if (p.path == "name") continue;
            auto it = base.find(p.path);
            if (it == base.end() || it->second != p.value) out[i].differences.push_back(p.path + "=" + p.value);
        }
    }
    return out;
}

void set_hw_param(HwConfig& config, const std::string& path, const std::string& value,
                  const std::string& file, int line) {
    Setter s(path, value, file, line);
    config.visit(s);
    if (!s.found()) throw InputError(file, line, path, "no such hardware parameter");
    if (path == "clock.core_mhz") config.clock.core_written = true;
    if (path == "clock.interconnect_mhz") config.clock.interconnect_written = true;
}

}  // namespace sfx
