// A backend's own noise on one shot against the simulated sensor's (dslr/render_noise.h): the
// measurement `--samples auto` is held to, shared by its test and bench/noise_table.cpp.
#pragma once

#include <filesystem>
#include <optional>
#include <string>

#include "dslr/render_noise.h"
#include "ir/ir.h"
#include "run/backend.h"

namespace rigc::run {

// Renders `shot` twice with `backend` into `work_dir`, the second time with the run's seed (and
// so the renderer's) one higher, and measures the two linear frames. Nullopt with `error` set
// when a render fails.
std::optional<dslr::RenderNoise> measure_renderer_noise(const ir::Scene& scene, Backend& backend,
                                                        RenderSettings settings, int shot,
                                                        const std::filesystem::path& work_dir,
                                                        std::string* error);

}  // namespace rigc::run
