// The one interface every renderer implements. A backend turns one shot of an instantiated scene
// into a linear frame (cd/m² and an object mask, on the canvas of dslr::render_geometry_for);
// the run loop (run/run_loop.h) owns everything else: the run folder, its lock, the manifest,
// skipping and resuming, progress, the DSLR model's development and the asynchronous writes.
// How to add one: docs/architecture.md, "Adding a backend".
#pragma once

#include <filesystem>
#include <map>
#include <memory>
#include <optional>
#include <string>

#include "dslr/frame.h"
#include "ir/ir.h"
#include "scene/studio_scene.h"

namespace rigc::run {

// RenderSettings::samples that asks a renderer to sample each pixel until its own noise is at
// most a quarter of the simulated sensor's noise variance (`--samples auto`; docs/fidelity.md).
inline constexpr int kConvergedSamples = -1;

// `text` as RenderSettings::samples: a whole number within 0..65536, or "auto" for
// kConvergedSamples; nullopt otherwise.
std::optional<int> parse_samples(const std::string& text);
// RenderSettings::samples as parse_samples reads it back ("auto" or the count).
std::string samples_text(int samples);

// What a run asks of every backend.
struct RenderSettings {
  double scale = 1.0;      // multiplies the sensor resolution
  std::uint64_t seed = 1;  // sensor noise (and an external renderer's sampling seed)
  int samples = 0;  // renderer samples per pixel; 0 = the backend's default; kConvergedSamples

  // False with a one-line `error` when a field is out of its domain.
  bool check(std::string* error) const;
};

class Backend;

// `settings` as `backend` takes them: kConvergedSamples is the default samples of a backend
// without noise of its own (Backend::converges).
RenderSettings settings_for(const Backend& backend, RenderSettings settings);

// One shot in linear light, as a backend rendered it.
struct RenderedShot {
  dslr::LinearFrame frame;               // rgb in cd/m², mask of the object
  bool depth_of_field_rendered = false;  // the renderer's lens blurred it: the DSLR model must not
  int subframes = 1;                     // motion-blur sub-frames averaged (1: none, or native)
  std::map<std::string, double> stage_ms;  // the backend's own stages, by name
};

// Where a backend may keep files of its own during a run, and where a shot's log goes.
struct ShotFiles {
  std::filesystem::path work_dir;  // <run>/render for backends with scripts; else empty
  std::filesystem::path log;       // the external program's log for this shot; else empty
};

// The frame a live view wants: its size as a share of the sensor's, and whether a draft serves
// (the frames while the camera or a slider moves may trade fidelity for speed).
struct FrameWish {
  double scale = 1;
  bool draft = false;
};

// A live view's renderer: frame after frame of one scene while the camera or a setting moves.
// It may keep what stays between frames (the preview keeps its shadow maps while the studio
// object, the angle and the size stay); `studio` is held so that its address stays unique.
class LiveRenderer {
 public:
  virtual ~LiveRenderer() = default;
  // One frame of `shot` as `wish` says. False with a one-line `error`.
  virtual bool render(const ir::Scene& scene,
                      const std::shared_ptr<const scene::StudioScene>& studio, const ir::Shot& shot,
                      FrameWish wish, RenderedShot* out, std::string* error) = 0;
};

class Backend {
 public:
  virtual ~Backend() = default;
  // The name `render --backend`, the manifest and the shot keys use.
  virtual std::string name() const = 0;

  // Whether the backend writes scripts a user can render by hand (`compile --target NAME`);
  // such a backend keeps them in the run's render/ folder and logs each shot there.
  virtual bool emits_scripts() const { return false; }
  // Whether RenderSettings::samples changes its output (then it is part of the shot key).
  virtual bool takes_samples() const { return false; }
  // The samples a pixel that RenderSettings::samples = 0 stands for, when one count says it (0
  // when the default is no count): asking for the default by number keeps the shot keys.
  virtual int default_samples() const { return 0; }
  // Whether kConvergedSamples samples differently from the default: a renderer with Monte Carlo
  // noise of its own. One without takes it as its default.
  virtual bool converges() const { return false; }
  // The backend's own options that change its output, as text for the shot key ("" when none
  // differs from the default).
  virtual std::string options_key() const { return ""; }
  // Raised whenever a correction changes what the backend renders from the same inputs; above 1
  // it joins the shot key, so a run rendered before the correction renders again.
  virtual int output_version() const { return 1; }

  // Checked before anything is written: e.g. that the external program is installed. False with
  // a one-line `error` naming what to install.
  virtual bool available(std::string* error) const;
  // Checked with the settings before anything is written: settings valid for every backend that
  // this one cannot honour. False with a one-line `error`.
  virtual bool check_settings(const RenderSettings& /*settings*/, std::string* /*error*/) const {
    return true;
  }
  // Writes the scripts into `dir` (which may not exist yet). False with a one-line `error`.
  virtual bool emit(const ir::Scene& scene, const scene::StudioScene& studio,
                    const std::filesystem::path& dir, const RenderSettings& settings,
                    std::string* error);
  // Called once per run, before the first shot that must render.
  virtual bool prepare(const ir::Scene& scene, const scene::StudioScene& studio,
                       const RenderSettings& settings, const ShotFiles& files, std::string* error);
  // A renderer for a live view (the studio's), or null when the backend is too slow for one.
  virtual std::unique_ptr<LiveRenderer> live_renderer() const { return nullptr; }
  // Renders one shot. False with a one-line `error`. (Seven parameters: the shot's inputs, its
  // files and its output; every backend's override has them.)
  virtual bool render(const ir::Scene& scene, const scene::StudioScene& studio,
                      const ir::Shot& shot, const RenderSettings& settings, const ShotFiles& files,
                      RenderedShot* out, std::string* error) = 0;
};

}  // namespace rigc::run
