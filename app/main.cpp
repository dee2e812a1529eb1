// sfx: a design-space explorer for stream-filtering ray-tracing hardware.
// Thin: parses, calls the libraries, prints. Bad input exits 2 with file, line and key.

#include <algorithm>
#include <iostream>
#include <vector>

#include "app/commands.h"
#include "base/input_error.h"

// libsystemc.so defines main() and calls sc_main(); sfx has its own main(), so this is never
// called, but the library needs the symbol to link.
extern "C" int sc_main(int, char**) { return 0; }

namespace {

size_t edit_distance(const std::string& a, const std::string& b) {
    std::vector<size_t> row(b.size() + 1);
    for (size_t j = 0; j <= b.size(); ++j) row[j] = j;
    for (size_t i = 1; i <= a.size(); ++i) {
        size_t diagonal = row[0];
        row[0] = i;
        for (size_t j = 1; j <= b.size(); ++j) {
            const size_t up = row[j];
            row[j] = std::min({row[j] + 1, row[j - 1] + 1, diagonal + (a[i - 1] != b[j - 1])});
            diagonal = up;
        }
    }
    return row[b.size()];
}

// CLI11 says only "argument was not expected"; name the command and the nearest one.
bool unknown_command(const CLI::App& app, const std::string& word) {
    if (word.empty() || word[0] == '-') return false;
    std::string nearest;
    size_t best = std::string::npos;
    for (const CLI::App* sub : app.get_subcommands([](const CLI::App*) { return true; })) {
        if (sub->check_name(word)) return false;
        if (sub->get_group().empty()) continue;  // hidden (run-group)
        const size_t d = edit_distance(word, sub->get_name());
        if (d < best) best = d, nearest = sub->get_name();
    }
    std::cerr << "sfx: error: unknown command '" << word << "'";
    if (best <= std::max<size_t>(2, word.size() / 3)) std::cerr << " (did you mean '" << nearest << "'?)";
    std::cerr << "; see sfx --help\n";
    return true;
}

}  // namespace

int main(int argc, char** argv) {
    CLI::App app{"sfx: hardware design-space explorer for stream-filtering ray tracing"};
    app.require_subcommand(1);
    sfx::add_render_command(app);
    sfx::add_trace_stats_command(app);
    sfx::add_validate_command(app);
    sfx::add_scene_info_command(app);
    sfx::add_simulate_command(app);
    sfx::add_accuracy_command(app);
    sfx::add_sweep_command(app);
    sfx::add_explore_command(app);
    sfx::add_compare_command(app);
    sfx::add_report_command(app);
    sfx::add_calibrate_command(app);
    sfx::strict_number_flags(app);
    if (argc > 1 && unknown_command(app, argv[1])) return 2;
    try {
        app.parse(argc, argv);
    } catch (const CLI::CallForHelp& e) {
        return app.exit(e);
    } catch (const CLI::CallForAllHelp& e) {
        return app.exit(e);
    } catch (const CLI::ParseError& e) {
        // The same prefix as every other bad value (CLI11's own text names the flag).
        std::cerr << "sfx: error: command line: " << e.what()
                  << "\nRun with --help for more information.\n";
        return 2;
    } catch (const sfx::InputError& e) {
        std::cerr << "sfx: error: " << e.what() << "\n";
        return 2;
    } catch (const std::exception& e) {
        std::cerr << "sfx: failed: " << e.what() << "\n";
        return 1;
    }
    return 0;
}
