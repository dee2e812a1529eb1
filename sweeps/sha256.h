#pragma once
// SHA-256 of a byte string, as lower-case hex: the results store's point key (OpenSSL's EVP
// digest does the hashing).

#include <string>

namespace sfx {

std::string sha256_hex(const std::string& bytes);

}  // namespace sfx
