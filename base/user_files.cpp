#include "base/user_files.h"

#include <fcntl.h>
#include <sys/stat.h>
#include <unistd.h>
#include <yaml-cpp/eventhandler.h>

#include <algorithm>
#include <cerrno>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <sstream>
#include <vector>

#include "base/input_error.h"

namespace sfx {
namespace {

std::string kind_of(mode_t mode) {
    if (S_ISDIR(mode)) return "a directory";
    if (S_ISFIFO(mode)) return "a FIFO";
    if (S_ISCHR(mode)) return "a character device";
    if (S_ISBLK(mode)) return "a block device";
    if (S_ISSOCK(mode)) return "a socket";
    return "not a regular file";
}

[[noreturn]] void fail_errno(const std::string& path, const std::string& what, int err) {
    throw InputError(path, 0, "", "cannot read " + what + ": " + std::strerror(err));
}

struct Fd {
    int fd;
    ~Fd() {
        if (fd >= 0) ::close(fd);
    }
};

int line_of(const YAML::Node& n) {
    return n.Mark().line >= 0 ? n.Mark().line + 1 : 0;
}

std::string join(const std::string& prefix, const std::string& name) {
    return prefix.empty() ? name : prefix + "." + name;
}

// The most nodes a document may hold with its aliases expanded: every sfx file is far
// smaller, and a few lines of nested aliases (`b: [*a, *a, ...]`) otherwise expand to
// billions of nodes that each reader would walk.
constexpr size_t k_max_yaml_nodes = 1000000;

// Keys must be scalars: `? [a]\n: 1` would otherwise escape every parser as a bad conversion.
void check_scalar_keys(const YAML::Node& node, const std::string& file, const std::string& path,
                       int depth, size_t& nodes) {
    if (depth > 256)
        throw InputError(file, line_of(node), path, "nested more than 256 levels deep");
    if (++nodes > k_max_yaml_nodes)
        throw InputError(
            file, line_of(node), path,
            "more than " + std::to_string(k_max_yaml_nodes) + " YAML nodes with aliases expanded");
    if (node.IsMap()) {
        for (const auto& kv : node) {
            if (!kv.first.IsScalar()) {
                YAML::Emitter key;
                key << YAML::Flow << kv.first;
                throw InputError(file, line_of(kv.first), join(path, key.c_str()),
                                 "a key must be a plain scalar, not a list or a mapping");
            }
            check_scalar_keys(kv.second, file, join(path, kv.first.Scalar()), depth + 1, nodes);
        }
    } else if (node.IsSequence()) {
        for (size_t i = 0; i < node.size(); ++i)
            check_scalar_keys(node[i], file, path + "[" + std::to_string(i) + "]", depth + 1,
                              nodes);
    }
}

// The line where the second document starts: its root node's, else the second marker's.
int second_document_line(int root_line, const std::string& text) {
    if (root_line > 0) return root_line;
    int line = 1, markers = 0, content_seen = 0;
    for (size_t i = 0; i < text.size(); i = text.find('\n', i) + 1, ++line) {
        const bool marker = text.compare(i, 3, "---") == 0 || text.compare(i, 3, "...") == 0;
        if (marker && (++markers > 1 || content_seen)) return line;
        if (!marker && text[i] != '#' && text[i] != '\n' && text[i] != '%') content_seen = 1;
        if (text.find('\n', i) == std::string::npos) break;
    }
    return 0;
}

// Records where each document's root node starts (the first node event after a document start).
class DocumentStarts : public YAML::EventHandler {
  public:
    std::vector<YAML::Mark> roots;
    void OnDocumentStart(const YAML::Mark&) override { m_want_root = true; }
    void OnDocumentEnd() override {}
    void OnNull(const YAML::Mark& m, YAML::anchor_t) override { root(m); }
    void OnAlias(const YAML::Mark& m, YAML::anchor_t) override { root(m); }
    void OnScalar(const YAML::Mark& m, const std::string&, YAML::anchor_t,
                  const std::string&) override {
        root(m);
    }
    void OnSequenceStart(const YAML::Mark& m, const std::string&, YAML::anchor_t,
                         YAML::EmitterStyle::value) override {
        root(m);
    }
    void OnSequenceEnd() override {}
    void OnMapStart(const YAML::Mark& m, const std::string&, YAML::anchor_t,
                    YAML::EmitterStyle::value) override {
        root(m);
    }
    void OnMapEnd() override {}

  private:
    void root(const YAML::Mark& m) {
        if (m_want_root) roots.push_back(m);
        m_want_root = false;
    }
    bool m_want_root = false;
};

}  // namespace

void check_regular_file(const std::string& path, const std::string& what) {
    struct stat st {};
    if (::stat(path.c_str(), &st) != 0) fail_errno(path, what, errno);
    if (!S_ISREG(st.st_mode))
        throw InputError(
            path, 0, "",
            "cannot read " + what + ": " + kind_of(st.st_mode) + ", not a regular file");
}

std::string read_input_file(const std::string& path, const std::string& what) {
    // O_NONBLOCK: opening a FIFO must not wait for a writer; fstat then refuses it.
    Fd f{::open(path.c_str(), O_RDONLY | O_NONBLOCK | O_CLOEXEC)};
    if (f.fd < 0) fail_errno(path, what, errno);
    struct stat st {};
    if (::fstat(f.fd, &st) != 0) fail_errno(path, what, errno);
    if (!S_ISREG(st.st_mode))
        throw InputError(
            path, 0, "",
            "cannot read " + what + ": " + kind_of(st.st_mode) + ", not a regular file");
    std::string text;
    std::vector<char> buf(1 << 16);
    for (;;) {
        const ssize_t n = ::read(f.fd, buf.data(), buf.size());
        if (n < 0 && errno == EINTR) continue;
        if (n < 0) fail_errno(path, what, errno);
        if (n == 0) break;
        text.append(buf.data(), size_t(n));
    }
    return text;
}

YAML::Node parse_yaml_document(const std::string& text, const std::string& file) {
    // Not YAML::LoadAll: yaml-cpp 0.7 loops for ever, allocating, on a stray ',' at the top level
    // (yaml-cpp issue 1040): its parser reports a new empty document at the same place again and
    // again. The documents are walked here instead, at most three, and a document that starts
    // where the last one did is that syntax error.
    YAML::Node root;
    int documents = 0, second_line = 0;
    try {
        root = YAML::Load(text);
        std::istringstream in(text);
        YAML::Parser parser(in);
        DocumentStarts starts;
        for (; documents < 3 && parser.HandleNextDocument(starts); ++documents) {
            const size_t n = starts.roots.size();
            if (n >= 2 && starts.roots[n - 1].pos == starts.roots[n - 2].pos) {
                const size_t at = size_t(std::max(0, starts.roots[n - 1].pos));
                throw InputError(file, starts.roots[n - 1].line + 1, "",
                                 "YAML syntax error: unexpected " +
                                     (at < text.size() ? "'" + text.substr(at, 1) + "'"
                                                       : std::string("end of file")));
            }
            if (documents == 1 && n >= 2) second_line = starts.roots[1].line + 1;
        }
    } catch (const YAML::Exception& e) {
        throw InputError(file, e.mark.line >= 0 ? e.mark.line + 1 : 0, "",
                         "YAML syntax error: " + e.msg);
    }
    if (documents > 1) {
        throw InputError(file, second_document_line(second_line, text), "",
                         "a second YAML document: the file must hold exactly one");
    }
    size_t nodes = 0;
    check_scalar_keys(root, file, "", 0, nodes);
    return root;
}

void check_output_file(const std::string& path, const std::string& flag) {
    auto fail = [&](const std::string& what) {
        throw InputError("command line", 0, flag, "cannot write '" + path + "': " + what);
    };
    if (path.empty()) fail("empty path");
    struct stat st {};
    if (::stat(path.c_str(), &st) == 0) {
        if (S_ISDIR(st.st_mode)) fail("it is a directory");
        if (!S_ISREG(st.st_mode)) fail(kind_of(st.st_mode) + ", not a regular file");
        if (::access(path.c_str(), W_OK) != 0)
            fail(std::string("the file is not writable: ") + std::strerror(errno));
    }
    std::string dir = std::filesystem::path(path).parent_path().string();
    if (dir.empty()) dir = ".";
    if (::stat(dir.c_str(), &st) != 0) fail("directory '" + dir + "' does not exist");
    if (!S_ISDIR(st.st_mode)) fail("'" + dir + "' is not a directory");
    if (::access(dir.c_str(), W_OK | X_OK) != 0)
        fail("directory '" + dir + "' is not writable: " + std::strerror(errno));
}

OutputFiles::~OutputFiles() {
    if (m_committed) return;
    for (const Entry& e : m_entries) std::remove(e.temp.c_str());
}

std::string OutputFiles::add(const std::string& path, const std::string& flag) {
    check_output_file(path, flag);
    const std::filesystem::path p(path);
    const std::string temp =
        (p.parent_path() / ("." + p.filename().string() + ".partial-" + std::to_string(::getpid())))
            .string();
    m_entries.push_back({path, temp, flag});
    return temp;
}

void OutputFiles::commit() {
    for (const Entry& e : m_entries)
        if (::access(e.temp.c_str(), F_OK) != 0)
            throw InputError("command line", 0, e.flag, "'" + e.path + "' was not written");
    for (const Entry& e : m_entries)
        if (std::rename(e.temp.c_str(), e.path.c_str()) != 0)
            throw InputError("command line", 0, e.flag,
                             "cannot write '" + e.path + "': " + std::strerror(errno));
    m_committed = true;
}

}  // namespace sfx
