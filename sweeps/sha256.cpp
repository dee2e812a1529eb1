#include "sweeps/sha256.h"

#include <openssl/evp.h>

#include <cstdio>
#include <stdexcept>

namespace sfx {

std::string sha256_hex(const std::string& bytes) {
    unsigned char digest[EVP_MAX_MD_SIZE];
    unsigned int length = 0;
    // One-shot EVP digest; it fails only when libcrypto cannot allocate or find SHA-256.
    if (EVP_Digest(bytes.data(), bytes.size(), digest, &length, EVP_sha256(), nullptr) != 1 ||
        length != 32)
        throw std::runtime_error("OpenSSL: SHA-256 digest failed");
    std::string out(2 * length, '0');
    for (unsigned int i = 0; i < length; ++i) std::snprintf(&out[2 * i], 3, "%02x", digest[i]);
    return out;
}

}  // namespace sfx
