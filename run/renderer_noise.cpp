#include "run/renderer_noise.h"

#include "scene/studio_scene.h"

namespace rigc::run {

std::optional<dslr::RenderNoise> measure_renderer_noise(const ir::Scene& scene, Backend& backend,
                                                        RenderSettings settings, int shot,
                                                        const std::filesystem::path& work_dir,
                                                        std::string* error) {
  settings = settings_for(backend, settings);
  const scene::StudioScene studio = scene::prepare_studio_scene(scene);
  const ShotFiles files{work_dir, work_dir / "log.txt"};
  std::filesystem::create_directories(work_dir);
  RenderedShot first, second;
  if (!backend.prepare(scene, studio, settings, files, error) ||
      !backend.render(scene, studio, scene.shots.at(shot), settings, files, &first, error)) {
    return std::nullopt;
  }
  ++settings.seed;
  if (!backend.render(scene, studio, scene.shots.at(shot), settings, files, &second, error)) {
    return std::nullopt;
  }
  return dslr::measure_render_noise(scene.camera, first.frame, second.frame);
}

}  // namespace rigc::run
