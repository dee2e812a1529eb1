// sfx: a design-space explorer for stream-filtering ray-tracing hardware.
// Thin: parses, calls the libraries, prints. Bad input exits 2 with file, line and key.

#include <iostream>

#include "app/commands.h"
#include "workloads/input_error.h"

// libsystemc.so defines main() and calls sc_main(); sfx has its own main(), so this is never
// called, but the library needs the symbol to link.
extern "C" int sc_main(int, char**) { return 0; }

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
    sfx::add_compare_command(app);
    sfx::add_report_command(app);
    try {
        app.parse(argc, argv);
    } catch (const CLI::CallForHelp& e) {
        return app.exit(e);
    } catch (const CLI::CallForAllHelp& e) {
        return app.exit(e);
    } catch (const CLI::ParseError& e) {
        app.exit(e);
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
