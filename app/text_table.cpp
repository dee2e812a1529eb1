#include "app/text_table.h"

#include <algorithm>
#include <cstdio>
#include <iomanip>
#include <sstream>

namespace sfx {

std::string fixed_text(double v, int digits) {
    std::ostringstream s;
    s << std::fixed << std::setprecision(digits) << v;
    return s.str();
}

std::string significant_text(double v) {
    char b[32];
    std::snprintf(b, sizeof b, "%.4g", v);
    return b;
}

void print_text_table(std::ostream& out, const std::vector<std::string>& headers,
                      const std::vector<std::vector<std::string>>& rows,
                      const std::function<bool(size_t column)>& left, const std::string& indent) {
    std::vector<size_t> width(headers.size());
    for (size_t c = 0; c < headers.size(); ++c) {
        width[c] = headers[c].size();
        for (const auto& r : rows) width[c] = std::max(width[c], r[c].size());
    }
    auto print = [&](const std::vector<std::string>& r) {
        std::string line;
        for (size_t c = 0; c < r.size(); ++c) {
            const std::string pad(width[c] - r[c].size(), ' ');
            line += (c ? "  " : "") + (left(c) ? r[c] + pad : pad + r[c]);
        }
        while (!line.empty() && line.back() == ' ') line.pop_back();
        out << indent << line << "\n";
    };
    print(headers);
    for (const auto& r : rows) print(r);
}

}  // namespace sfx
