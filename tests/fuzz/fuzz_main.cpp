// One libFuzzer binary per target: SFX_FUZZ_TARGET names the function of fuzz_targets.h.
#include "tests/fuzz/fuzz_targets.h"

// libsystemc.so defines main() and calls sc_main(); libFuzzer provides main(), so this is never
// called, but the shared library needs the symbol to link.
extern "C" int sc_main(int, char**) {
    return 0;
}

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
    sfx::fuzz::SFX_FUZZ_TARGET(data, size);
    return 0;
}
