#include "backends/registry.h"

#include "backends/cycles/cycles_backend.h"
#include "backends/povray/povray_backend.h"
#include "backends/preview/preview_backend.h"

namespace rigc::backends {

namespace {

template <typename T>
std::unique_ptr<run::Backend> make() {
  return std::make_unique<T>();
}

}  // namespace

const std::vector<BackendEntry>& registry() {
  static const std::vector<BackendEntry> entries = {
      {"preview", "RigC's rasterizer: seconds for a whole capture", make<preview::PreviewBackend>},
      {"povray", "POV-Ray 3.7 ray tracing (reference)", make<povray::PovrayBackend>},
      {"cycles", "Blender Cycles path tracing (reference)", make<cycles::CyclesBackend>},
  };
  return entries;
}

const BackendEntry* find_backend(std::string_view name) {
  for (const auto& entry : registry()) {
    if (entry.name == name) return &entry;
  }
  return nullptr;
}

std::vector<std::string> backend_names(bool scripts_only) {
  std::vector<std::string> names;
  for (const auto& entry : registry()) {
    if (!scripts_only || entry.make()->emits_scripts()) names.push_back(entry.name);
  }
  return names;
}

}  // namespace rigc::backends
