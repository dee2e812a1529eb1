#define CATCH_CONFIG_MAIN
#include <catch2/catch.hpp>

// libsystemc.so defines main() and calls sc_main(); Catch2 provides main(), so this is never
// called, but the library needs the symbol to link.
extern "C" int sc_main(int, char**) { return 0; }
