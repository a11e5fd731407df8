// The compiler's entry points: scene file -> IR, through parse, check and lower.
#pragma once

#include <optional>
#include <string>

#include "compiler/diagnostics.h"
#include "compiler/spec.h"
#include "ir/ir.h"

namespace rigc {

// Resolves a checked scene into the IR: loads or builds the mesh, places the object on the
// turntable, computes intrinsics, aims lights and expands shots. Reports problems at their lines.
std::optional<ir::Scene> lower_scene(const spec::SceneSpec& scene, DiagnosticEngine& diag);

// The whole front end on scene text (`file` names it in diagnostics; relative mesh paths are
// resolved against `base_dir`).
std::optional<ir::Scene> compile_scene_text(const std::string& text, const std::string& file,
                                            const std::string& base_dir, DiagnosticEngine& diag);

// A scene file's text, read up to the scene size limit; nullopt after a diagnostic when it is
// unreadable or larger.
std::optional<std::string> read_scene_file(const std::string& path, DiagnosticEngine& diag);

// Reads and compiles a scene file; an unreadable file is a diagnostic too.
std::optional<ir::Scene> compile_scene_file(const std::string& path, DiagnosticEngine& diag);

}  // namespace rigc
