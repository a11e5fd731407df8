// The files a scene was compiled from, protected from every writer of this process
// (io/input_files.h): `compile -o model.obj` once wrote the IR over the scene's mesh.
#pragma once

#include <string>

#include "ir/ir.h"

namespace rigc::run {

// Protects the scene file, the object's mesh and the material libraries an OBJ names, and the
// texture files.
void protect_scene_inputs(const std::string& scene_path, const ir::Scene& scene);

// The same but the scene file: for a scene compiled from text (a sweep's variant).
void protect_scene_files(const ir::Scene& scene);

}  // namespace rigc::run
