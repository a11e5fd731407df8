// `rigc compile --target cycles` and `rigc render --backend cycles`: the scene as one Python
// script for Blender 3.x (`blender -b --factory-startup --python scene.py`) plus its binary
// geometry (geometry.bin) and textures, rendered by Cycles and developed by the shared DSLR model.
//
// Everything the script needs is one JSON document inside it, written as an escaped Python string
// literal (external::python_string_literal): no user text is ever code. Paths in the script are
// relative to its own folder. Units: Blender's, 1 m per unit; lights in watts (point, spot, area),
// suns in W/m² = lux/683, the ambient as a world of radiance E/(683π), the output EXR in
// W/(m²·sr) = cd/m² / 683.
#pragma once

#include <filesystem>
#include <iosfwd>
#include <memory>
#include <string>
#include <vector>

#include "backends/external/reference_backend.h"
#include "ir/ir.h"

namespace rigc::cycles {

using external::ReferenceOptions;
using external::ShotTiming;

// Writes scene.py, geometry.bin and the textures into `dir` (created if missing). `samples` is
// the default Cycles sample count of the script (0: 64). False with a one-line `error`.
bool emit(const ir::Scene& scene, const std::filesystem::path& dir, double scale,
          std::string* error, int samples = 0);

// Emits into <output_dir>/render, runs Blender once per shot, develops and writes the common
// layout. Exit code 0, 1 user error, 2 Blender failure.
int run(const ir::Scene& scene, const ReferenceOptions& options, std::ostream& log,
        std::vector<ShotTiming>* timings = nullptr);

std::unique_ptr<external::Renderer> make_renderer();

}  // namespace rigc::cycles
