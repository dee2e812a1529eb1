#pragma once
// Bad input (a scene, a mesh, a config, a command-line value) is reported with the file, the
// line and the dotted key it came from. Parsers throw this; only app/ turns it into exit code 2.

#include <stdexcept>
#include <string>

namespace sfx {

class InputError : public std::runtime_error {
public:
    InputError(const std::string& file, int line, const std::string& key, const std::string& what)
        : std::runtime_error(format(file, line, key, what)), m_file(file), m_line(line), m_key(key),
          m_message(what) {}

    const std::string& file() const { return m_file; }
    int line() const { return m_line; }  // 1-based; 0 when unknown
    const std::string& key() const { return m_key; }
    // What is wrong, without the file, line and key (to re-throw it under another key).
    const std::string& message() const { return m_message; }

private:
    static std::string format(const std::string& file, int line, const std::string& key,
                              const std::string& what) {
        std::string s = file;
        if (line > 0) s += ":" + std::to_string(line);
        if (!key.empty()) s += ": " + key;
        return s + ": " + what;
    }
    std::string m_file;
    int m_line;
    std::string m_key;
    std::string m_message;
};

}  // namespace sfx
