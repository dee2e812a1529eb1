// Every input saved in tests/fuzz/ (the seeds checked in here and each crash a fuzzer found,
// in regressions/<target>/) replayed through the same target functions the fuzzers run: a
// fixed bug stays fixed in every ordinary build, and under the sanitizers.

#include <catch2/catch.hpp>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <string>

#include "tests/fuzz/fuzz_targets.h"

using namespace sfx;

TEST_CASE("fuzz regressions and seeds replay cleanly", "[fuzz]") {
    const std::filesystem::path root = std::filesystem::path(SFX_SOURCE_DIR) / "tests" / "fuzz";
    size_t replayed = 0;
    for (const fuzz::TargetInfo& t : fuzz::targets()) {
        for (const char* kind : {"regressions", "seeds"}) {
            const auto dir = root / kind / t.name;
            if (!std::filesystem::is_directory(dir)) continue;
            for (const auto& entry : std::filesystem::directory_iterator(dir)) {
                if (!entry.is_regular_file() || entry.path().filename() == "README.md") continue;
                std::ifstream in(entry.path(), std::ios::binary);
                const std::string bytes((std::istreambuf_iterator<char>(in)), {});
                INFO(t.name << ": " << entry.path().string());
                t.run(reinterpret_cast<const uint8_t*>(bytes.data()), bytes.size());
                ++replayed;
            }
        }
    }
    CHECK(replayed > 0);
}
