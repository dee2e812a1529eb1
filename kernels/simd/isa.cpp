#include "kernels/simd/isa.h"

#include "base/input_error.h"

namespace sfx {

const char* isa_name(Isa isa) {
    switch (isa) {
        case Isa::automatic:
            return "auto";
        case Isa::scalar:
            return "scalar";
        case Isa::avx2:
            return "avx2";
        case Isa::avx512:
            return "avx512";
    }
    return "?";
}

uint32_t isa_width(Isa isa) {
    switch (isa) {
        case Isa::avx512:
            return 16;
        case Isa::avx2:
            return 8;
        default:
            return 1;
    }
}

Isa parse_isa(const std::string& text, const std::string& flag) {
    for (Isa isa : {Isa::automatic, Isa::scalar, Isa::avx2, Isa::avx512})
        if (text == isa_name(isa)) return isa;
    throw InputError("command line", 0, flag,
                     "'" + text + "' is not an instruction set (auto, avx512, avx2, scalar)");
}

bool isa_supported(Isa isa) {
    // libgcc's cpuid checks also ask the OS (XGETBV) whether it saves the wide registers.
    __builtin_cpu_init();
    switch (isa) {
        case Isa::avx512:
            return __builtin_cpu_supports("avx512f") && __builtin_cpu_supports("avx512bw") &&
                   __builtin_cpu_supports("avx512vl") && __builtin_cpu_supports("avx512vbmi2");
        case Isa::avx2:
            return __builtin_cpu_supports("avx2");
        default:
            return true;
    }
}

Isa best_isa() {
    if (isa_supported(Isa::avx512)) return Isa::avx512;
    if (isa_supported(Isa::avx2)) return Isa::avx2;
    return Isa::scalar;
}

Isa resolve_isa(Isa requested, const std::string& flag) {
    if (requested == Isa::automatic) return best_isa();
    if (!isa_supported(requested))
        throw InputError("command line", 0, flag,
                         std::string("this CPU cannot run ") + isa_name(requested) +
                             " (the widest it supports is " + isa_name(best_isa()) + ")");
    return requested;
}

std::string describe_isa(Isa isa) {
    const Isa resolved = isa == Isa::automatic ? best_isa() : isa;
    return std::string(isa_name(resolved)) + " (" + std::to_string(isa_width(resolved)) +
           (resolved == Isa::scalar ? " lane)" : " lanes)");
}

std::vector<Isa> supported_isas() {
    std::vector<Isa> out{Isa::scalar};
    for (Isa isa : {Isa::avx2, Isa::avx512})
        if (isa_supported(isa)) out.push_back(isa);
    return out;
}

}  // namespace sfx
