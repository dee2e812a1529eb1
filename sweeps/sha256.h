#pragma once
// SHA-256 (FIPS 180-4) of a byte string, as lower-case hex: the results store's point key.
// Small and self-contained so the store does not pull in a crypto library.

#include <string>

namespace sfx {

std::string sha256_hex(const std::string& bytes);

}  // namespace sfx
