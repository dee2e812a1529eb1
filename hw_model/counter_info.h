#pragma once
// A counter's identity, declared once next to the counter as gem5's ADD_STAT does: its dotted
// name, unit and description. Every sum, difference, scaling and listing of a counter struct
// walks its counters through a static visit(a, b, f) that calls f(info, counter of a, counter
// of b); a visit of one struct passes it as both. The name is joined only when asked for, so
// sums stay cheap.

#include <cstddef>
#include <string>

namespace sfx {

struct CounterInfo {
    static constexpr int k_parts = 6;
    const char* parts[k_parts] = {};  // outermost group first; joined with '.'
    const char* unit = "";
    const char* description = "";

    CounterInfo(const char* name, const char* unit_, const char* description_)
        : parts{name}, unit(unit_), description(description_) {}
    // The same counter inside a group: "group." + name.
    CounterInfo under(const char* group) const {
        CounterInfo c = *this;
        for (int i = k_parts - 1; i > 0; --i) c.parts[i] = c.parts[i - 1];
        c.parts[0] = group;
        return c;
    }
    std::string name() const {
        std::string n;
        for (const char* p : parts)
            if (p) n += (n.empty() ? "" : ".") + std::string(p);
        return n;
    }
};

// The name of index i of an array of counters ("0" .. "15"): cache levels.
inline const char* index_name(size_t i) {
    static const char* names[] = {"0", "1", "2",  "3",  "4",  "5",  "6",  "7",
                                  "8", "9", "10", "11", "12", "13", "14", "15"};
    return i < sizeof names / sizeof names[0] ? names[i] : "?";
}

}  // namespace sfx
