#pragma once
// The files a user names, read and written one way everywhere. Inputs: only regular files (a
// FIFO, a device or a directory is refused, never opened blocking); YAML holds exactly one
// document. Outputs: checked before any work starts, then written whole or not at all
// (a temporary file beside the target, renamed over it). Errors are InputErrors naming the
// file, or the flag that named it.

#include <yaml-cpp/yaml.h>

#include <functional>
#include <string>
#include <vector>

namespace sfx {

// Throws InputError(path, 0, "", ...) unless `path` names an existing regular file.
// `what` says what the file was to be ("sweep file"); it starts the message.
void check_regular_file(const std::string& path, const std::string& what);

// The whole file, after check_regular_file.
std::string read_input_file(const std::string& path, const std::string& what);

// Parses YAML text holding one document (an empty text is one null document). A syntax
// error, a second document or a non-scalar mapping key anywhere is an InputError naming
// `file` and the line.
YAML::Node parse_yaml_document(const std::string& text, const std::string& file);

// Throws InputError("command line", 0, flag, ...) unless a file can be created or replaced at
// `path`: its directory exists and is writable, and `path` is not a directory.
void check_output_file(const std::string& path, const std::string& flag);

// Outputs written together: each is written to a temporary file beside its target; commit()
// renames them all into place, and if commit() is never reached the temporaries are removed,
// so a failure leaves no output (and no half of a pair) behind.
class OutputFiles {
  public:
    OutputFiles() = default;
    OutputFiles(const OutputFiles&) = delete;
    OutputFiles& operator=(const OutputFiles&) = delete;
    ~OutputFiles();

    // Checks `path` now (check_output_file) and returns the temporary path to write it to.
    std::string add(const std::string& path, const std::string& flag);
    void commit();

  private:
    struct Entry {
        std::string path, temp, flag;
    };
    std::vector<Entry> m_entries;
    bool m_committed = false;
};

}  // namespace sfx
