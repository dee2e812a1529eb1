#pragma once
// The fuzzed entry points, one function per target, shared by the libFuzzer binaries
// (fuzz_main.cpp, clang only) and by the replay test that runs every saved input in an
// ordinary build (replay_test.cpp). Each returns normally when the input was accepted or
// refused the documented way; any other outcome (an escaping exception of another type, a
// broken invariant) aborts, which libFuzzer and Catch2 both report as a failure.

#include <cstddef>
#include <cstdint>
#include <string>
#include <vector>

namespace sfx::fuzz {

using Target = void (*)(const uint8_t* data, size_t size);

struct TargetInfo {
    const char* name;  // also the folder of its seeds and regressions
    Target run;
};

// hw_config: parse; if accepted, dump -> parse -> dump must give the same text.
void hw_config(const uint8_t* data, size_t size);
// scene: a *.scene.yaml file (meshes resolved beside a temporary copy), loaded and checked.
void scene(const uint8_t* data, size_t size);
// sweep: a *.sweep.yaml, resolved against sweeps/, expanded (at most the expansion cap).
void sweep(const uint8_t* data, size_t size);
// explore: an explore file (sfx explore), resolved against sweeps/; every configuration's
// positions round-trip and its points are made and keyed.
void explore(const uint8_t* data, size_t size);
// mesh_obj, mesh_ply: a mesh file through assimp; accepted meshes are finite and indexed right.
void mesh_obj(const uint8_t* data, size_t size);
void mesh_ply(const uint8_t* data, size_t size);
// store: arbitrary bytes opened as a results store (read-only and read-write) and read.
void store(const uint8_t* data, size_t size);
// trace: the binary trace reader, replayed into a sink that checks every op against its pass.
void trace(const uint8_t* data, size_t size);

const std::vector<TargetInfo>& targets();

}  // namespace sfx::fuzz
