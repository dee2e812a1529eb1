#include "kernels/trace.h"

#include <algorithm>
#include <cstdio>
#include <cstring>
#include <memory>
#include <stdexcept>
#include <type_traits>

#include "base/input_error.h"
#include "base/user_files.h"

namespace sfx {

const char* to_string(OpStage stage) {
    switch (stage) {
        case OpStage::traversal:
            return "traversal";
        case OpStage::intersection:
            return "intersection";
        case OpStage::shading:
            return "shading";
    }
    return "?";
}

// ---- CountingSink -------------------------------------------------------------------------

double CountingSink::StageCounts::utilization(size_t width_index, uint32_t width) const {
    const uint64_t g = groups[width_index];
    return g ? double(lanes) / (double(width) * double(g)) : 0.0;
}

CountingSink::CountingSink(std::vector<uint32_t> widths) : m_widths(std::move(widths)) {
    for (uint32_t w : m_widths)
        if (w == 0) throw std::invalid_argument("CountingSink: SIMD width must be >= 1");
    for (auto& secondary : m_stages)
        for (StageCounts& s : secondary) {
            s.groups.assign(m_widths.size(), 0);
            s.histogram.assign(k_histogram_buckets, 0);
        }
}

void CountingSink::begin_pass(const TilePass&) {
    ++m_passes;
    m_traced_generation = -1;
}

void CountingSink::end_pass(const TilePass& p) {
    m_generations += p.generations;
}

void TraceSink::ops_of_length(OpKind kind, OpStage stage, uint16_t generation, uint32_t length,
                              uint32_t count, uint32_t passed, uint32_t failed_candidates) {
    StreamOp o{kind, stage, generation, k_no_object, length};
    for (uint32_t i = 0; i < count; ++i) {  // the passes and failed candidates fill the ops in turn
        o.pass_count = std::min(passed, length);
        passed -= o.pass_count;
        o.failed_candidates = std::min(failed_candidates, length - o.pass_count);
        failed_candidates -= o.failed_candidates;
        op(o);
    }
}

namespace {
uint32_t bounce_slot(uint32_t generation) {
    return std::min(generation, CountingSink::k_bounce_slots - 1);
}
}  // namespace

void CountingSink::op(const StreamOp& op) {
    CountingSink::ops_of_length(op.kind, op.stage, op.generation, op.length, 1, op.pass_count,
                                op.failed_candidates);
}

void CountingSink::ops_of_length(OpKind kind, OpStage stage, uint16_t generation, uint32_t length,
                                 uint32_t count, uint32_t passed, uint32_t) {
    if (count == 0 || length == 0) return;
    const uint64_t lanes = uint64_t(count) * length;
    StageCounts& s = m_stages[generation > 0][uint32_t(stage)];
    s.ops += count;
    s.lanes += lanes;
    s.passed += passed;
    uint64_t* groups = s.groups.data();
    const uint32_t* widths = m_widths.data();
    for (size_t i = 0, n = m_widths.size(); i < n; ++i)
        groups[i] += uint64_t(count) * lane_groups(length, widths[i]);
    s.histogram[31u - uint32_t(__builtin_clz(length))] += count;        // length > 0: below 32
    const uint32_t slot = bounce_slot(generation);
    KindTally& k = m_kinds[slot][uint32_t(kind)];
    k.ops += count;
    k.lanes += lanes;
    // A batched generation (RayGrid) enters with the cell walk at the root, before any box test.
    if ((kind == OpKind::box_test || kind == OpKind::raygrid_walk) &&
        int32_t(generation) != m_traced_generation) {
        m_rays[slot] += length;  // the generation's entry test: one lane per ray
        m_traced_generation = generation;
    }
}

uint64_t CountingSink::kind_ops(OpKind k) const {
    uint64_t sum = 0;
    for (const auto& slot : m_kinds) sum += slot[uint32_t(k)].ops;
    return sum;
}

namespace {
// Slot 0 (generation 0 alone) for primary streams, the sum of the later slots for secondary.
template <class PerSlot>
uint64_t primary_or_secondary(bool secondary, uint32_t slots, PerSlot per_slot) {
    if (!secondary) return per_slot(0u);
    uint64_t sum = 0;
    for (uint32_t slot = 1; slot < slots; ++slot) sum += per_slot(slot);
    return sum;
}
}  // namespace

uint64_t CountingSink::kind_lanes(OpKind k) const {
    return kind_lanes(k, false) + kind_lanes(k, true);
}

uint64_t CountingSink::kind_lanes(OpKind k, bool secondary) const {
    return primary_or_secondary(secondary, k_bounce_slots,
                                [&](uint32_t slot) { return m_kinds[slot][uint32_t(k)].lanes; });
}

uint64_t CountingSink::rays() const {
    return rays(false) + rays(true);
}

uint64_t CountingSink::rays(bool secondary) const {
    return primary_or_secondary(secondary, k_bounce_slots,
                                [&](uint32_t slot) { return m_rays[slot]; });
}

CountingSink::BounceCounts CountingSink::bounce(uint32_t generation) const {
    const uint32_t slot = bounce_slot(generation);
    const auto& k = m_kinds[slot];
    const auto box = uint32_t(OpKind::box_test), triangle = uint32_t(OpKind::triangle_test),
               sphere = uint32_t(OpKind::sphere_test);
    BounceCounts b;
    b.rays = m_rays[slot];
    b.box_ops = k[box].ops;
    b.box_lanes = k[box].lanes;
    b.prim_ops = k[triangle].ops + k[sphere].ops;
    b.prim_lanes = k[triangle].lanes + k[sphere].lanes;
    return b;
}

CountingSink& CountingSink::operator+=(const CountingSink& o) {
    if (o.m_widths != m_widths) throw std::invalid_argument("CountingSink: widths differ");
    for (int g = 0; g < 2; ++g)
        for (uint32_t st = 0; st < k_op_stage_count; ++st) {
            StageCounts& a = m_stages[g][st];
            const StageCounts& b = o.m_stages[g][st];
            a.ops += b.ops;
            a.lanes += b.lanes;
            a.passed += b.passed;
            for (size_t i = 0; i < a.groups.size(); ++i) a.groups[i] += b.groups[i];
            for (size_t i = 0; i < a.histogram.size(); ++i) a.histogram[i] += b.histogram[i];
        }
    for (uint32_t slot = 0; slot < k_bounce_slots; ++slot) {
        for (uint32_t k = 0; k < k_op_kind_count; ++k) {
            m_kinds[slot][k].ops += o.m_kinds[slot][k].ops;
            m_kinds[slot][k].lanes += o.m_kinds[slot][k].lanes;
        }
        m_rays[slot] += o.m_rays[slot];
    }
    m_passes += o.m_passes;
    m_generations += o.m_generations;
    return *this;
}

// ---- Trace file ---------------------------------------------------------------------------
// Little-endian, as the host writes it (the tree targets x86-64 and aarch64 hosts):
//   header: "SFXTRACE" u32 version u64 scene_hash, then TraceFrame's fields in its visit()
//           order (u32 width height spp tile max_depth u64 seed u8 primary_entry reorder
//           u32 reorder_lod_ppm u8 batching u32 batching_queue batching_cell_prims)
//   pass:   u8 'P' u32 tile x0 y0 x1 y1 sample slot_count
//   op:     u8 'O' u8 kind u8 stage u16 generation u32 object length pass_count
//           failed_candidates (version 4 on) u8 starts_traversal (version 5 on: 1 starts,
//           version 6 on: 3 starts with its rays sharing one origin, StreamOp::origin_shared) u32
//           slots[length] u8 passed_bits[ceil(length/8)] (bit i of byte i/8, LSB first)
//   end:    u8 'E' u32 generations        (end of pass)
//   frame:  u8 'F'                         (end of file)

static const char k_magic[8] = {'S', 'F', 'X', 'T', 'R', 'A', 'C', 'E'};

TraceFileWriter::TraceFileWriter(const std::string& path) : m_path(path), m_tmp(path + ".partial") {
    m_file = std::fopen(m_tmp.c_str(), "wb");
    if (!m_file) throw std::runtime_error("cannot write " + path);
}

TraceFileWriter::~TraceFileWriter() {
    if (m_file) {  // end_frame never came: leave nothing half-written behind
        std::fclose(m_file);
        std::remove(m_tmp.c_str());
    }
}

void TraceFileWriter::write(const void* data, size_t n) {
    if (std::fwrite(data, 1, n, m_file) != n) throw std::runtime_error("cannot write " + m_path);
    m_bytes += n;
}

template <class T>
static void put(std::vector<uint8_t>& out, T v) {
    const auto* b = reinterpret_cast<const uint8_t*>(&v);
    out.insert(out.end(), b, b + sizeof(T));
}

void TraceFileWriter::begin_frame(const TraceHeader& h) {
    std::vector<uint8_t> b(k_magic, k_magic + 8);
    put(b, TraceHeader::k_version);
    put(b, h.scene_hash);
    TraceFrame frame = h;
    frame.visit([&](auto& field) { put(b, field); });
    write(b.data(), b.size());
}

void TraceFileWriter::begin_pass(const TilePass& p) {
    std::vector<uint8_t> b{uint8_t('P')};
    for (uint32_t v : {p.tile, p.x0, p.y0, p.x1, p.y1, p.sample, p.slot_count}) put(b, v);
    write(b.data(), b.size());
}

void TraceFileWriter::op(const StreamOp& op) {
    m_bits.clear();
    m_bits.push_back(uint8_t('O'));
    m_bits.push_back(uint8_t(op.kind));
    m_bits.push_back(uint8_t(op.stage));
    put(m_bits, op.generation);
    put(m_bits, op.object);
    put(m_bits, op.length);
    put(m_bits, op.pass_count);
    put(m_bits, op.failed_candidates);
    m_bits.push_back(uint8_t(op.starts_traversal) | uint8_t(op.origin_shared && op.starts_traversal)
                                                        << 1);
    write(m_bits.data(), m_bits.size());
    write(op.slots, size_t(op.length) * 4);
    m_bits.assign((op.length + 7) / 8, 0);
    for (uint32_t i = 0; i < op.length; ++i)
        if (op.passed[i]) m_bits[i >> 3] |= uint8_t(1u << (i & 7));
    write(m_bits.data(), m_bits.size());
}

void TraceFileWriter::end_pass(const TilePass& p) {
    std::vector<uint8_t> b{uint8_t('E')};
    put(b, p.generations);
    write(b.data(), b.size());
}

void TraceFileWriter::end_frame() {
    const uint8_t f = 'F';
    write(&f, 1);
    const bool ok = std::fclose(m_file) == 0;
    m_file = nullptr;
    if (!ok || std::rename(m_tmp.c_str(), m_path.c_str()) != 0) {
        std::remove(m_tmp.c_str());
        throw std::runtime_error("cannot write " + m_path);
    }
}

namespace {
// Reads a trace file that may be anything: every count is checked against the bytes left and
// every slot against its pass before it is used, so a bad file is a clear InputError naming
// the byte offset, never a huge allocation or a slot past the ray buffer.
struct Reader {
    std::FILE* f;
    const std::string& path;
    uint64_t size = 0, offset = 0;
    [[noreturn]] void fail(const std::string& what) const {
        throw InputError(
            path, 0, "",
            "not a valid sfx trace: " + what + " (at byte " + std::to_string(offset) + ")");
    }
    void read(void* p, size_t n) {
        if (n > size - offset || std::fread(p, 1, n, f) != n) fail("truncated");
        offset += n;
    }
    template <class T>
    T get() {
        T v;
        read(&v, sizeof v);
        return v;
    }
};
}  // namespace

// A file that is not a whole, consistent trace is an InputError naming the file and the byte
// offset; the sink may have seen ops before it (the reader streams).
TraceHeader read_trace_file(const std::string& path, TraceSink& sink) {
    check_regular_file(path, "trace");
    std::unique_ptr<std::FILE, int (*)(std::FILE*)> file(std::fopen(path.c_str(), "rb"),
                                                         &std::fclose);
    if (!file) throw InputError(path, 0, "", "cannot read the trace");
    Reader r{file.get(), path};
    if (std::fseek(file.get(), 0, SEEK_END) != 0) r.fail("cannot seek");
    r.size = uint64_t(std::ftell(file.get()));
    std::rewind(file.get());
    char magic[8];
    r.read(magic, 8);
    if (std::memcmp(magic, k_magic, 8) != 0) throw InputError(path, 0, "", "not an sfx trace");
    TraceHeader h;
    h.version = r.get<uint32_t>();
    if (h.version < 1 || h.version > TraceHeader::k_version)
        throw InputError(path, 0, "",
                         "trace version " + std::to_string(h.version) + ", this sfx reads 1 to " +
                             std::to_string(TraceHeader::k_version));
    h.scene_hash = r.get<uint64_t>();
    // An older header ends early: the later fields keep their defaults.
    const uint32_t fields = h.version == 1   ? TraceFrame::k_version1_fields
                            : h.version == 2 ? TraceFrame::k_version2_fields
                                             : ~0u;
    uint32_t field = 0;
    h.visit([&](auto& v) {
        if (field++ < fields) v = r.get<std::remove_reference_t<decltype(v)>>();
    });
    if (uint8_t(h.primary_entry) > uint8_t(PrimaryEntry::aepsa) ||
        uint8_t(h.reorder) > uint8_t(RayReorder::hit_point) ||
        uint8_t(h.batching) > uint8_t(RayBatching::raygrid))
        r.fail("unknown primary_entry, reorder or batching in the header");
    sink.begin_frame(h);
    TilePass pass;
    bool in_pass = false;
    std::vector<uint32_t> slots;
    std::vector<uint8_t> bits, passed;
    for (;;) {
        const uint8_t tag = r.get<uint8_t>();
        if (tag == 'F') {
            if (in_pass) r.fail("the frame ends inside a tile pass");
            if (r.offset != r.size) r.fail("bytes after the end of the frame");
            break;
        }
        if (tag == 'P') {
            if (in_pass) r.fail("a tile pass starts inside another");
            pass = TilePass{};
            pass.tile = r.get<uint32_t>();
            pass.x0 = r.get<uint32_t>();
            pass.y0 = r.get<uint32_t>();
            pass.x1 = r.get<uint32_t>();
            pass.y1 = r.get<uint32_t>();
            pass.sample = r.get<uint32_t>();
            pass.slot_count = r.get<uint32_t>();
            if (pass.x0 >= pass.x1 || pass.x1 > h.width || pass.y0 >= pass.y1 || pass.y1 > h.height)
                r.fail("a tile pass outside the image");
            if (uint64_t(pass.slot_count) != uint64_t(pass.x1 - pass.x0) * (pass.y1 - pass.y0))
                r.fail("a tile pass whose slot count is not its pixel count");
            in_pass = true;
            sink.begin_pass(pass);
        } else if (tag == 'O') {
            if (!in_pass) r.fail("an operation outside a tile pass");
            StreamOp op;
            op.kind = OpKind(r.get<uint8_t>());
            op.stage = OpStage(r.get<uint8_t>());
            if (uint32_t(op.kind) >= k_op_kind_count || uint32_t(op.stage) >= k_op_stage_count)
                r.fail("bad op kind or stage");
            op.generation = r.get<uint16_t>();
            op.object = r.get<uint32_t>();
            op.length = r.get<uint32_t>();
            op.pass_count = r.get<uint32_t>();
            if (h.version >= 4) op.failed_candidates = r.get<uint32_t>();
            if (h.version >= 5) {
                const uint8_t starts = r.get<uint8_t>();
                if (starts > (h.version >= 6 ? 3 : 1) || starts == 2)
                    r.fail(h.version >= 6 ? "a traversal-start flag that is not 0, 1 or 3"
                                          : "a traversal-start flag that is neither 0 nor 1");
                op.starts_traversal = (starts & 1) != 0;
                op.origin_shared = (starts & 2) != 0;
            }
            if (op.length > pass.slot_count) r.fail("an operation longer than its tile pass");
            if (op.failed_candidates > op.length - std::min(op.pass_count, op.length))
                r.fail("more failed candidates than failing lanes");
            if (uint64_t(op.length) * 4 > r.size - r.offset)
                r.fail("truncated");  // before allocating
            slots.resize(op.length);
            r.read(slots.data(), size_t(op.length) * 4);
            for (uint32_t s : slots)
                if (s >= pass.slot_count) r.fail("a ray slot past its tile pass");
            bits.resize((op.length + 7) / 8);
            r.read(bits.data(), bits.size());
            passed.resize(op.length);
            uint32_t count = 0;
            for (uint32_t i = 0; i < op.length; ++i) {
                passed[i] = (bits[i >> 3] >> (i & 7)) & 1u;
                count += passed[i];
            }
            if (count != op.pass_count) r.fail("a pass count that disagrees with its pass bits");
            op.slots = slots.data();
            op.passed = passed.data();
            sink.op(op);
        } else if (tag == 'E') {
            if (!in_pass) r.fail("a tile pass ends that never began");
            pass.generations = r.get<uint32_t>();
            in_pass = false;
            sink.end_pass(pass);
        } else {
            r.fail("bad record tag");
        }
    }
    sink.end_frame();
    return h;
}

// ---- TraceRecorder ------------------------------------------------------------------------

void TraceRecorder::begin_pass(const TilePass& p) {
    clear();
    m_pass = p;
}

void TraceRecorder::op(const StreamOp& op) {
    m_ops.push_back({op.kind, op.stage, op.generation, op.object, op.length, op.pass_count,
                     op.failed_candidates, op.starts_traversal, op.origin_shared, m_slots.size()});
    m_slots.insert(m_slots.end(), op.slots, op.slots + op.length);
    m_passed.insert(m_passed.end(), op.passed, op.passed + op.length);
}

void TraceRecorder::end_pass(const TilePass& p) {
    m_pass = p;
}

void TraceRecorder::replay(TraceSink& sink) const {
    sink.begin_pass(m_pass);
    for (const Record& r : m_ops) {
        StreamOp op;
        op.kind = r.kind;
        op.stage = r.stage;
        op.generation = r.generation;
        op.object = r.object;
        op.length = r.length;
        op.pass_count = r.pass_count;
        op.failed_candidates = r.failed_candidates;
        op.starts_traversal = r.starts_traversal;
        op.origin_shared = r.origin_shared;
        op.slots = m_slots.data() + r.offset;
        op.passed = m_passed.data() + r.offset;
        sink.op(op);
    }
    sink.end_pass(m_pass);
}

void TraceRecorder::clear() {
    m_ops.clear();
    m_slots.clear();
    m_passed.clear();
}

}  // namespace sfx
