#include "kernels/render.h"

#include <png.h>

#include <algorithm>
#include <atomic>
#include <cmath>
#include <cstdio>
#include <fstream>
#include <memory>
#include <mutex>
#include <sstream>
#include <stdexcept>
#include <thread>

namespace sfx {

Vec3 Image::mean() const {
    double r = 0, g = 0, b = 0;
    for (const Vec3& p : pixels) { r += p.x; g += p.y; b += p.z; }
    const double n = pixels.empty() ? 1.0 : double(pixels.size());
    return {float(r / n), float(g / n), float(b / n)};
}

RenderStats& RenderStats::operator+=(const RenderStats& o) {
    camera_rays += o.camera_rays;
    extension_rays += o.extension_rays;
    shadow_rays += o.shadow_rays;
    nonfinite_paths += o.nonfinite_paths;
    for (int i = 0; i < 3; ++i) stage_tsc[i] += o.stage_tsc[i];
    for (int i = 0; i < 2; ++i) short_loop_tsc[i] += o.short_loop_tsc[i];
    for (int i = 0; i < 2; ++i) short_loop_leaf_tsc[i] += o.short_loop_leaf_tsc[i];
    for (uint32_t k = 0; k < k_op_kind_count; ++k) shading_op_tsc[k] += o.shading_op_tsc[k];
    ray_setup_tsc += o.ray_setup_tsc;
    shading_rest_tsc += o.shading_rest_tsc;
    part_tsc.insert(part_tsc.end(), o.part_tsc.begin(), o.part_tsc.end());
    part_start_tsc.insert(part_start_tsc.end(), o.part_start_tsc.begin(), o.part_start_tsc.end());
    entry_searches += o.entry_searches;
    entry_depth_sum += o.entry_depth_sum;
    batch_queues += o.batch_queues;
    batch_full_queues += o.batch_full_queues;
    batch_queued_rays += o.batch_queued_rays;
    return *this;
}

// Files are written to a temporary name and renamed, so a failed write leaves nothing behind.
static void commit_file(const std::string& tmp, const std::string& path) {
    if (std::rename(tmp.c_str(), path.c_str()) != 0) {
        std::remove(tmp.c_str());
        throw std::runtime_error("cannot write " + path);
    }
}

void write_pfm(const Image& image, const std::string& path) {
    const std::string tmp = path + ".partial";
    {
        std::ofstream out(tmp, std::ios::binary);
        if (!out) throw std::runtime_error("cannot write " + path);
        out << "PF\n" << image.width << " " << image.height << "\n-1.0\n";  // little-endian
        for (uint32_t y = image.height; y-- > 0;)  // PFM stores the bottom row first
            for (uint32_t x = 0; x < image.width; ++x) {
                const Vec3& p = image.at(x, y);
                const float rgb[3] = {p.x, p.y, p.z};
                out.write(reinterpret_cast<const char*>(rgb), sizeof rgb);
            }
        if (!out) throw std::runtime_error("cannot write " + path);
    }
    commit_file(tmp, path);
}

Image read_pfm(const std::string& path) {
    std::ifstream in(path, std::ios::binary);
    std::string magic;
    uint32_t w = 0, h = 0;
    float scale = 0;
    in >> magic >> w >> h >> scale;
    in.get();
    if (!in || magic != "PF" || scale >= 0) throw std::runtime_error(path + ": not a little-endian RGB PFM");
    Image image(w, h);
    for (uint32_t y = h; y-- > 0;)
        for (uint32_t x = 0; x < w; ++x) {
            float rgb[3];
            in.read(reinterpret_cast<char*>(rgb), sizeof rgb);
            image.at(x, y) = {rgb[0], rgb[1], rgb[2]};
        }
    if (!in) throw std::runtime_error(path + ": truncated PFM");
    return image;
}

static uint8_t to_srgb8(float v) {
    if (!(v > 0.f)) return 0;
    v = std::min(v, 1.f);
    const float s = v <= 0.0031308f ? 12.92f * v : 1.055f * std::pow(v, 1.f / 2.4f) - 0.055f;
    return uint8_t(std::lround(s * 255.f));
}

void write_png(const Image& image, const std::string& path) {
    const std::string tmp = path + ".partial";
    FILE* file = std::fopen(tmp.c_str(), "wb");
    if (!file) throw std::runtime_error("cannot write " + path);
    png_structp png = png_create_write_struct(PNG_LIBPNG_VER_STRING, nullptr, nullptr, nullptr);
    png_infop info = png ? png_create_info_struct(png) : nullptr;
    if (!png || !info || setjmp(png_jmpbuf(png))) {
        png_destroy_write_struct(&png, &info);
        std::fclose(file);
        std::remove(tmp.c_str());
        throw std::runtime_error("cannot write " + path);
    }
    png_init_io(png, file);
    png_set_IHDR(png, info, image.width, image.height, 8, PNG_COLOR_TYPE_RGB, PNG_INTERLACE_NONE,
                 PNG_COMPRESSION_TYPE_DEFAULT, PNG_FILTER_TYPE_DEFAULT);
    png_write_info(png, info);
    std::vector<uint8_t> row(size_t(image.width) * 3);
    for (uint32_t y = 0; y < image.height; ++y) {
        for (uint32_t x = 0; x < image.width; ++x) {
            const Vec3& p = image.at(x, y);
            row[3 * x] = to_srgb8(p.x);
            row[3 * x + 1] = to_srgb8(p.y);
            row[3 * x + 2] = to_srgb8(p.z);
        }
        png_write_row(png, row.data());
    }
    png_write_end(png, nullptr);
    png_destroy_write_struct(&png, &info);
    std::fclose(file);
    commit_file(tmp, path);
}

std::vector<TileRect> make_tiles(uint32_t width, uint32_t height, uint32_t tile_size) {
    if (tile_size == 0) throw std::invalid_argument("tile size must be >= 1");
    std::vector<TileRect> tiles;
    for (uint32_t y = 0; y < height; y += tile_size)
        for (uint32_t x = 0; x < width; x += tile_size)
            tiles.push_back({x, y, std::min(width, x + tile_size), std::min(height, y + tile_size)});
    return tiles;
}

void parallel_for(uint32_t count, uint32_t threads, const std::function<void(uint32_t)>& job) {
    if (threads == 0) threads = std::max(1u, std::thread::hardware_concurrency());
    threads = std::min(threads, std::max(1u, count));
    std::atomic<uint32_t> next{0};
    std::exception_ptr error;
    std::mutex error_mutex;
    auto worker = [&] {
        for (uint32_t i; (i = next.fetch_add(1)) < count;) {
            try {
                job(i);
            } catch (...) {
                std::lock_guard<std::mutex> lock(error_mutex);
                if (!error) error = std::current_exception();
            }
        }
    };
    std::vector<std::thread> pool;
    for (uint32_t t = 1; t < threads; ++t) pool.emplace_back(worker);
    worker();
    for (std::thread& t : pool) t.join();
    if (error) std::rethrow_exception(error);
}

}  // namespace sfx
