// The fuzz harnesses' entry points: each feeds one input, as bytes, to a reader of outside data
// the way RigC reads it. The libFuzzer harnesses (fuzz/*_fuzzer.cpp) and the regression test
// (fuzz/regressions_test.cpp, replaying tests/fuzz_regressions/<harness>/) call the same ones.
// A reader may reject its input with an error; it must not crash, hang or throw.
#pragma once

#include <span>
#include <string_view>

namespace rigc::fuzz {

using Entry = void (*)(std::string_view input);

struct Harness {
  const char* name;  // fuzz/<name>_fuzzer.cpp, tests/fuzz_regressions/<name>/
  Entry entry;
};

// Every harness, in a fixed order.
std::span<const Harness> harnesses();

// A scene's text through parse, check and lower (relative mesh paths against scenes/).
void scene(std::string_view input);
// A model file through load_model, as .ply, .obj, .stl, or .gltf (.glb when it starts with the
// binary glTF magic).
void ply(std::string_view input);
void obj(std::string_view input);
void stl(std::string_view input);
void gltf(std::string_view input);
// Encoded image bytes (PNG, JPEG, ...) through the texture decoder models use.
void texture(std::string_view input);
// COLMAP text models as eval reads them.
void colmap_cameras(std::string_view input);
void colmap_images(std::string_view input);
void colmap_points(std::string_view input);
// A run folder's manifest.json.
void manifest(std::string_view input);
// A studio edit request: its route on the first line, its body after, answered by one session
// on the studio's test scene.
void studio_edits(std::string_view input);

}  // namespace rigc::fuzz
