// Every backend RigC has, by name. `render --backend`, `compile --target`, `compare --backends`
// and the verbs to come read this one list; adding a backend is a folder plus one line in
// registry.cpp (docs/architecture.md, "Adding a backend").
#pragma once

#include <functional>
#include <memory>
#include <string>
#include <string_view>
#include <vector>

#include "run/backend.h"

namespace rigc::backends {

struct BackendEntry {
  std::string name;                                     // as `--backend NAME` takes it
  std::string summary;                                  // one line for help texts
  std::function<std::unique_ptr<run::Backend>()> make;  // a fresh backend for one run
};

const std::vector<BackendEntry>& registry();

// The entry called `name`, or null.
const BackendEntry* find_backend(std::string_view name);

// The backends' names in registry order; with `scripts_only`, those that emit scripts.
std::vector<std::string> backend_names(bool scripts_only = false);

}  // namespace rigc::backends
