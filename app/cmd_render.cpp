// sfx render SCENE: renders a scene and writes a PNG and a float image (PFM) beside it.

#include <iostream>
#include <nlohmann/json.hpp>

#include "app/commands.h"
#include "kernels/bvh.h"
#include "kernels/reference/reference_tracer.h"
#include "kernels/stream/stream_tracer.h"
#include "base/input_error.h"
#include "workloads/scene_loader.h"
#include "base/user_files.h"

namespace sfx {

void add_render_command(CLI::App& app) {
    struct Options {
        std::string scene;
        std::string output = "render.png";
        std::string tracer = "reference";
        std::string trace;
        bool json = false;
        WorkloadFlags workload;
    };
    auto options = std::make_shared<Options>();
    CLI::App* c = app.add_subcommand("render", "render a scene to PNG and PFM");
    c->add_option("scene", options->scene, "scene file or built-in scene name")->required();
    c->add_option("-o,--output", options->output, "output PNG; the PFM goes beside it")
        ->capture_default_str();
    c->add_option("--tracer", options->tracer, "reference or stream (bit-identical images)")
        ->check(CLI::IsMember({"reference", "stream"}))
        ->capture_default_str();
    c->add_option("--trace", options->trace,
                  "stream tracer: write the workload trace (binary, see kernels/trace.cpp)");
    c->add_flag("--json", options->json, "print one JSON document");
    options->workload.add_to(c);
    c->callback([options] {
        if (options->output.size() < 5 || options->output.substr(options->output.size() - 4) != ".png")
            throw InputError("command line", 0, "--output", "expected a .png path, got '" + options->output + "'");
        if (!options->trace.empty() && options->tracer != "stream")
            throw InputError("command line", 0, "--trace", "needs --tracer stream");
        // Every output is checked before the render, and all appear together or none does.
        const std::string pfm = options->output.substr(0, options->output.size() - 4) + ".pfm";
        OutputFiles outputs;
        const std::string png_temp = outputs.add(options->output, "--output");
        const std::string pfm_temp = outputs.add(pfm, "--output (the PFM beside it)");
        const std::string trace_temp = options->trace.empty() ? "" : outputs.add(options->trace, "--trace");
        const Scene scene = load_scene(options->scene);
        const RenderSettings settings = options->workload.resolve(scene);
        const Bvh bvh(scene);
        std::unique_ptr<TraceFileWriter> writer;
        if (!options->trace.empty()) writer = std::make_unique<TraceFileWriter>(trace_temp);
        const RenderResult result = options->tracer == "stream"
                                        ? render_stream(scene, bvh, settings, writer.get())
                                        : render_reference(scene, bvh, settings);
        write_png(result.image, png_temp);
        write_pfm(result.image, pfm_temp);
        outputs.commit();
        const Vec3 mean = result.image.mean();
        if (options->json) {
            nlohmann::json j;
            j["scene"] = scene.name;
            j["tracer"] = options->tracer;
            j["width"] = settings.width;
            j["height"] = settings.height;
            j["spp"] = settings.spp;
            j["rays"] = result.stats.rays();
            j["rays.camera"] = result.stats.camera_rays;
            j["rays.extension"] = result.stats.extension_rays;
            j["rays.shadow"] = result.stats.shadow_rays;
            j["nonfinite_paths"] = result.stats.nonfinite_paths;
            j["host_seconds"] = result.stats.host_seconds;
            j["isa"] = isa_name(settings.isa);
            j["mean_radiance"] = {mean.x, mean.y, mean.z};
            j["png"] = options->output;
            j["pfm"] = pfm;
            if (writer) {
                j["trace"] = options->trace;
                j["trace_bytes"] = writer->bytes_written();
            }
            std::cout << j.dump(2) << "\n";
        } else {
            std::cout << "scene            " << scene.name << "\n"
                      << "image            " << settings.width << "x" << settings.height << " x "
                      << settings.spp << " spp, depth " << settings.max_depth << "\n"
                      << "stream back end  " << describe_isa(settings.isa) << "\n"
                      << "rays             " << result.stats.rays() << " (camera "
                      << result.stats.camera_rays << ", extension " << result.stats.extension_rays
                      << ", shadow " << result.stats.shadow_rays << ")\n"
                      << "nonfinite paths  " << result.stats.nonfinite_paths << "\n"
                      << "host seconds     " << result.stats.host_seconds << "\n"
                      << "mrays/s          " << result.stats.rays() / result.stats.host_seconds * 1e-6 << "\n"
                      << "wrote            " << options->output << ", " << pfm
                      << (writer ? ", " + options->trace + " (" +
                                       std::to_string(writer->bytes_written()) + " bytes)"
                                 : std::string())
                      << "\n";
        }
    });
}

}  // namespace sfx
