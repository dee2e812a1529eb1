#define CATCH_CONFIG_MAIN
#include <catch2/catch.hpp>

#include "base/core_contention.h"

// A test that times the host waits out another hardware thread on its core for 30 s at most
// (base/core_contention.h), so that a busy machine lengthens the suite by little.
static const bool g_contention_budget = [] {
    sfx::core_contention().set_total_wait_ms(30000.0);
    return true;
}();

// libsystemc.so defines main() and calls sc_main(); Catch2 provides main(), so this is never
// called, but the library needs the symbol to link.
extern "C" int sc_main(int, char**) { return 0; }
