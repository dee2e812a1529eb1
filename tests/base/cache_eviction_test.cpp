// evict_caches' size: three times the largest cache sysfs reports, at least 256 MiB.

#include "base/cache_eviction.h"

#include <catch2/catch.hpp>
#include <filesystem>
#include <fstream>

using namespace sfx;

TEST_CASE("The caches are evicted by three times the largest one, at least 256 MiB", "[base]") {
    namespace fs = std::filesystem;
    const fs::path dir = fs::temp_directory_path() / "sfx-cache-eviction-test";
    fs::remove_all(dir);
    // The Intel Xeon VM of family 6 model 0xCF: 48 KiB L1D, 32 KiB L1I, 2 MiB L2, 260 MiB L3.
    const char* sizes[] = {"48K", "32K", "2048K", "266240K"};
    for (int i = 0; i < 4; ++i) {
        fs::create_directories(dir / ("index" + std::to_string(i)));
        std::ofstream(dir / ("index" + std::to_string(i)) / "size") << sizes[i] << "\n";
    }
    CHECK(largest_cache_bytes(dir.string()) == uint64_t(266240) << 10);
    CHECK(eviction_bytes(largest_cache_bytes(dir.string())) == uint64_t(3 * 266240) << 10);
    // A Zen 3 core's 32 MiB L3: 256 MiB, as before.
    std::ofstream(dir / "index3" / "size") << "32M\n";
    CHECK(largest_cache_bytes(dir.string()) == uint64_t(32) << 20);
    CHECK(eviction_bytes(largest_cache_bytes(dir.string())) == k_min_eviction_bytes);
    // No sysfs: 256 MiB.
    fs::remove_all(dir);
    CHECK(largest_cache_bytes(dir.string()) == 0);
    CHECK(eviction_bytes(0) == k_min_eviction_bytes);
}
