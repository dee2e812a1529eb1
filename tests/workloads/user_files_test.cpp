// The files a user names: only regular files are read, YAML holds one document with plain
// keys, and outputs appear whole and together or not at all.

#include "base/user_files.h"

#include <sys/stat.h>

#include <catch2/catch.hpp>
#include <filesystem>
#include <fstream>

#include "tests/temp_dir.h"
#include "base/input_error.h"

using namespace sfx;
namespace fs = std::filesystem;

TEST_CASE("user files: only regular files are read, never a FIFO or a directory", "[workloads]") {
    const TempDir dir("sfx-user-files-test");
    const std::string fifo = (dir.path / "in.fifo").string();
    REQUIRE(::mkfifo(fifo.c_str(), 0600) == 0);
    // Without a writer, a blocking open would hang here.
    CHECK_THROWS_WITH(read_input_file(fifo, "scene file"),
                      Catch::Contains("a FIFO, not a regular file"));
    CHECK_THROWS_WITH(read_input_file(dir.path.string(), "scene file"),
                      Catch::Contains("a directory"));
    CHECK_THROWS_WITH(check_regular_file("/dev/null", "mesh"), Catch::Contains("character device"));
    CHECK_THROWS_WITH(read_input_file((dir.path / "none").string(), "mesh"),
                      Catch::Contains("No such file"));
    std::ofstream(dir.path / "a.yaml") << "x: 1\n";
    CHECK(read_input_file((dir.path / "a.yaml").string(), "x") == "x: 1\n");
}

TEST_CASE("user files: one YAML document with plain keys", "[workloads]") {
    CHECK(parse_yaml_document("", "e.yaml").IsNull());
    CHECK(parse_yaml_document("a: 1\n", "a.yaml")["a"].Scalar() == "1");
    try {
        parse_yaml_document("a: 1\n---\nb: 2\n", "two.yaml");
        FAIL("a second document was accepted");
    } catch (const InputError& e) {
        CHECK(e.file() == "two.yaml");
        CHECK(e.line() == 3);
    }
    try {
        parse_yaml_document("a:\n  - {b: 1, ? [c] : 2}\n", "k.yaml");
        FAIL("a list key was accepted");
    } catch (const InputError& e) {
        CHECK(e.line() == 2);
        CHECK(e.key() == "a[0].[c]");
    }
    CHECK_THROWS_AS(parse_yaml_document("a: [1, 2\n", "s.yaml"), InputError);
}

TEST_CASE("user files: aliases may not expand a document past its node budget", "[workloads]") {
    // Ten aliases a level, nine levels: 10^9 nodes from ten lines. Without the budget every
    // reader walks them all (minutes, then memory); with it, one error at once.
    std::string bomb = "a0: &a0 [x, x, x, x, x, x, x, x, x, x]\n";
    for (int i = 1; i < 10; ++i) {
        bomb += "a" + std::to_string(i) + ": &a" + std::to_string(i) + " [";
        for (int k = 0; k < 10; ++k) bomb += (k ? ", *a" : "*a") + std::to_string(i - 1);
        bomb += "]\n";
    }
    CHECK_THROWS_WITH(parse_yaml_document(bomb, "bomb.yaml"),
                      Catch::Contains("more than 1000000 YAML nodes with aliases expanded"));
    // A few aliases stay usable.
    CHECK(parse_yaml_document("a: &w 16\nb: *w\n", "ok.yaml")["b"].Scalar() == "16");
}

TEST_CASE("user files: outputs are checked first and appear together or not at all",
          "[workloads]") {
    const TempDir dir("sfx-user-files-test");
    const std::string a = (dir.path / "a.png").string(), b = (dir.path / "a.pfm").string();
    CHECK_THROWS_WITH(check_output_file((dir.path / "no" / "x.csv").string(), "--csv"),
                      Catch::Contains("--csv") && Catch::Contains("does not exist"));
    CHECK_THROWS_WITH(check_output_file(dir.path.string(), "--output"),
                      Catch::Contains("is a directory"));
    {
        OutputFiles out;
        std::ofstream(out.add(a, "--output")) << "png";
        std::ofstream(out.add(b, "--output")) << "pfm";
        // No commit: as if the second write had failed.
    }
    CHECK(fs::is_empty(dir.path));
    {
        OutputFiles out;
        std::ofstream(out.add(a, "--output")) << "png";
        out.add(b, "--output");  // never written: commit refuses and renames nothing
        CHECK_THROWS_WITH(out.commit(), Catch::Contains("was not written"));
    }
    CHECK(fs::is_empty(dir.path));
    {
        OutputFiles out;
        std::ofstream(out.add(a, "--output")) << "png";
        std::ofstream(out.add(b, "--output")) << "pfm";
        out.commit();
    }
    CHECK(fs::file_size(a) == 3);
    CHECK(fs::file_size(b) == 3);
    CHECK(std::distance(fs::directory_iterator(dir.path), fs::directory_iterator()) == 2);
}

// Found by the hw_config fuzzer (tests/fuzz/regressions/hw_config/): yaml-cpp's LoadAll loops
// for ever, allocating, on a stray ',' at the top level. It must be a syntax error at once.
TEST_CASE("user files: a stray top-level comma is a syntax error, not an endless loop",
          "[workloads]") {
    using Catch::Matchers::Contains;
    CHECK_THROWS_WITH(parse_yaml_document(",\n", "c.yaml"),
                      Contains("c.yaml:1: YAML syntax error: unexpected ','"));
    CHECK_THROWS_WITH(parse_yaml_document("# a comment\n, # x\n", "c.yaml"),
                      Contains("c.yaml:2: YAML syntax error"));
    // Documents that are not stuck keep their own messages and lines.
    CHECK(parse_yaml_document("---\na: 1\n...\n", "m.yaml")["a"].Scalar() == "1");
    CHECK_THROWS_WITH(parse_yaml_document("a: 1\n---\n", "e.yaml"),
                      Contains("a second YAML document"));
}
