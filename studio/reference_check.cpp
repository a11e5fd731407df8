#include "studio/reference_check.h"

#include <fmt/format.h>
#include <sys/resource.h>
#include <unistd.h>

#include <fstream>
#include <regex>
#include <sstream>

#include "backends/registry.h"
#include "io/child_processes.h"
#include "run/colmap_text.h"
#include "run/run_loop.h"
#include "studio/frame_encoding.h"

namespace rigc::studio {
namespace {

namespace fs = std::filesystem;
using Clock = std::chrono::steady_clock;

std::string read_text(const fs::path& path) {
  std::ifstream in(path, std::ios::binary);
  std::ostringstream text;
  text << in.rdbuf();
  return text.str();
}

}  // namespace

double render_progress_from_log(const std::string& log_text) {
  static const std::regex kPovray(R"(Rendered (\d+) of (\d+) pixels)");
  static const std::regex kBlender(R"(Sample (\d+)/(\d+))");
  double progress = -1;
  for (const std::regex* pattern : {&kPovray, &kBlender}) {
    for (auto it = std::sregex_iterator(log_text.begin(), log_text.end(), *pattern);
         it != std::sregex_iterator(); ++it) {
      const double done = std::stod((*it)[1]), total = std::stod((*it)[2]);
      if (total > 0) progress = std::clamp(done / total, 0.0, 1.0);
    }
  }
  return progress;
}

ReferenceCheck::ReferenceCheck(fs::path run_root) : run_root_(std::move(run_root)) {}

ReferenceCheck::~ReferenceCheck() {
  cancel();
  if (worker_.joinable()) worker_.join();
}

bool ReferenceCheck::start(std::shared_ptr<const ir::Scene> view, double scale,
                           std::string preview_jpeg, const ReferenceRequest& request,
                           std::string* error) {
  const backends::BackendEntry* entry = backends::find_backend(request.backend);
  if (!entry || request.backend == "preview") {
    *error = fmt::format("the reference is rendered by one of: {}",
                         fmt::join(backends::backend_names(true), ", "));
    return false;
  }
  if (!entry->make()->available(error)) return false;
  std::lock_guard lock(mutex_);
  if (running_) {
    *error = "a reference render is in progress: cancel it first";
    return false;
  }
  if (worker_.joinable()) worker_.join();
  running_ = true;
  cancelled_ = false;
  state_ = "running";
  backend_ = request.backend;
  message_.clear();
  log_ = run_root_ / request.backend / "render" / (view->shots.front().name + ".log");
  started_ = Clock::now();
  pending_preview_ = std::move(preview_jpeg);
  worker_ = std::thread(&ReferenceCheck::render, this, std::move(view), scale, request);
  return true;
}

// The worker: the run loop renders and develops the one shot into the run folder; the image it
// wrote becomes the reference.
void ReferenceCheck::render(std::shared_ptr<const ir::Scene> view, double scale,
                            ReferenceRequest request) {
  // Below the live view: this thread, and the renderer it starts, run at a lower priority.
  setpriority(PRIO_PROCESS, static_cast<id_t>(gettid()), 10);
  std::unique_ptr<run::Backend> backend = backends::find_backend(request.backend)->make();
  run::RunOptions options;
  options.output_dir = run_root_ / request.backend;
  options.settings.scale = scale;
  options.settings.samples = request.samples;
  std::ostringstream report;
  const int code = run::run_backend(*view, *backend, options, report);
  if (cancelled_) return finish("cancelled", "cancelled");
  if (code != 0) return finish("failed", report.str());
  const fs::path image =
      options.output_dir / run::image_relative_path(view->camera, view->shots.front());
  std::string error;
  int width = 0, height = 0;
  std::string jpeg = jpeg_of_image_file(image.string(), 90, &width, &height, &error);
  if (jpeg.empty()) return finish("failed", error);
  {
    std::lock_guard lock(mutex_);
    reference_jpeg_ = std::move(jpeg);
    preview_jpeg_ = std::move(pending_preview_);
    width_ = width;
    height_ = height;
  }
  finish("done", fmt::format("rendered with {} into {}", request.backend, image.string()));
}

void ReferenceCheck::finish(const std::string& state, const std::string& message) {
  std::lock_guard lock(mutex_);
  state_ = state;
  message_ = message;
  elapsed_s_ = std::chrono::duration<double>(Clock::now() - started_).count();
  running_ = false;
}

void ReferenceCheck::cancel() {
  cancelled_ = true;
  // The renderer may be between its two programs (image, mask): stop each as it starts.
  while (running_) {
    stop_child_processes();
    std::this_thread::sleep_for(std::chrono::milliseconds(50));
  }
}

nlohmann::json ReferenceCheck::status() const {
  std::lock_guard lock(mutex_);
  const bool running = state_ == "running";
  const double elapsed =
      running ? std::chrono::duration<double>(Clock::now() - started_).count() : elapsed_s_;
  const double progress = running ? render_progress_from_log(read_text(log_)) : 1;
  return {{"state", state_},
          {"backend", backend_},
          {"elapsed_s", elapsed},
          {"progress", progress >= 0 ? nlohmann::json(progress) : nlohmann::json()},
          {"message", message_},
          {"log", log_.string()},
          {"width", width_},
          {"height", height_}};
}

std::string ReferenceCheck::image(const std::string& which) const {
  std::lock_guard lock(mutex_);
  return which == "preview" ? preview_jpeg_ : reference_jpeg_;
}

}  // namespace rigc::studio
