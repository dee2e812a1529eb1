#pragma once
// A plain-text table for stdout: columns padded to their widest cell, two spaces apart, no
// trailing blanks. Used by the commands that print one row per point or configuration.

#include <functional>
#include <ostream>
#include <string>
#include <vector>

namespace sfx {

// A table cell: `v` with `digits` after the point ("12.50").
std::string fixed_text(double v, int digits);
// A table cell: `v` to 4 significant digits ("145", "0.3458").
std::string significant_text(double v);

// `left(c)`: whether column c is left-aligned (else right-aligned); each line starts with
// `indent`. Every row has the headers' column count.
void print_text_table(std::ostream& out, const std::vector<std::string>& headers,
                      const std::vector<std::vector<std::string>>& rows,
                      const std::function<bool(size_t column)>& left, const std::string& indent = "");

}  // namespace sfx
