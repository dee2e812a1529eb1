#pragma once
// The host instruction set the stream filters run with, chosen at run time from the CPU's
// features, so one binary runs on every x86-64 machine:
//   avx512  16 lanes (AVX-512 F/BW/VL/VBMI2; vpcompressd is the paper's in-place partition)
//   avx2     8 lanes (compress by permutation table)
//   scalar   1 lane
// The image and the workload trace never depend on it (the trace describes the modelled
// machine at its configured width, not the host).

#include <cstdint>
#include <string>
#include <vector>

namespace sfx {

enum class Isa : uint8_t { automatic, scalar, avx2, avx512 };

const char* isa_name(Isa isa);
uint32_t isa_width(Isa isa);  // lanes per filter group
// "auto", "avx512", "avx2", "scalar"; throws InputError("command line", 0, flag) otherwise.
Isa parse_isa(const std::string& text, const std::string& flag = "--isa");
bool isa_supported(Isa isa);  // the CPU (and OS) can run it; automatic and scalar: always
Isa best_isa();               // the widest supported
// automatic -> best_isa(); an unsupported request throws InputError naming `flag`.
Isa resolve_isa(Isa requested, const std::string& flag = "--isa");
std::vector<Isa> supported_isas();  // scalar first, then wider ones the machine has
std::string describe_isa(Isa isa);  // "avx512 (16 lanes)"; automatic: what it resolves to

}  // namespace sfx
