// Checks of command-line values shared by every command. Number flags: plain decimal text in
// the type's range. CLI11 alone reads "-1" into an unsigned as 2^64-1,
// "99999999999999999999999" as 2^64-1, "010" as octal and "0x10" as hex; here each is an error
// naming the flag (exit 2).

#include "app/commands.h"
#include "base/strict_number.h"

namespace sfx {
namespace {

std::string strict_unsigned(std::string& text) {
    uint64_t v = 0;
    if (!parse_unsigned(text, v))
        return "expected a non-negative decimal integer up to 18446744073709551615, got '" + text +
               "'";
    text = std::to_string(v);  // canonical: no leading zeros for CLI11 to read as octal
    return "";
}

std::string strict_signed(std::string& text) {
    int64_t v = 0;
    if (!parse_signed(text, v)) return "expected a decimal integer, got '" + text + "'";
    text = std::to_string(v);
    return "";
}

std::string strict_finite(std::string& text) {
    double v = 0.0;
    if (!parse_finite(text, v)) return "expected a finite decimal number, got '" + text + "'";
    return "";
}

void apply(CLI::App* app) {
    for (CLI::Option* o : app->get_options()) {
        // The type name, then any validator's: "UINT", "UINT:POSITIVE", "INT", "FLOAT".
        const std::string type = o->get_type_name();
        const std::string base = type.substr(0, type.find(':'));
        if (base == "UINT")
            o->transform(CLI::Validator(strict_unsigned, "", "strict unsigned"));
        else if (base == "INT")
            o->transform(CLI::Validator(strict_signed, "", "strict integer"));
        else if (base == "FLOAT")
            o->transform(CLI::Validator(strict_finite, "", "strict finite"));
    }
    for (CLI::App* sub : app->get_subcommands([](CLI::App*) { return true; })) apply(sub);
}

}  // namespace

void strict_number_flags(CLI::App& app) {
    apply(&app);
}

}  // namespace sfx
