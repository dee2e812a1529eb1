#pragma once
// A fresh, uniquely named directory under the system temp dir, removed with its contents by
// the destructor. CTest runs every test case as its own process, in parallel: tests that
// write files must never share a path.

#include <stdlib.h>

#include <filesystem>
#include <stdexcept>
#include <string>

namespace sfx {

struct TempDir {
    std::filesystem::path path;
    explicit TempDir(const std::string& prefix = "sfx-test") {
        std::string templ =
            (std::filesystem::temp_directory_path() / (prefix + "-XXXXXX")).string();
        if (!::mkdtemp(templ.data())) throw std::runtime_error("mkdtemp failed for " + templ);
        path = templ;
    }
    ~TempDir() {
        std::error_code ec;
        std::filesystem::remove_all(path, ec);
    }
    TempDir(const TempDir&) = delete;
    TempDir& operator=(const TempDir&) = delete;
};

}  // namespace sfx
