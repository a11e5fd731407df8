// A sweep's variants: the grid (or zipped pairs) of axis values, each an edited copy of the
// scene's text compiled before anything runs, and their folders out/<sweep>/<variant>/.
#pragma once

#include <filesystem>
#include <nlohmann/json.hpp>
#include <optional>
#include <string>
#include <vector>

#include "compiler/diagnostics.h"
#include "sweep/sweep_spec.h"

namespace rigc::sweep {

struct Variant {
  std::string name;                 // its folder's name
  std::vector<int> value_index;     // per axis
  std::vector<std::string> values;  // per axis, as written
  std::string backend;
  std::string scene_text;  // the scene with the values written in
  std::string key;         // hash of everything that changes its outputs
};

// Every combination: zipped axes move together, the groups form a grid (first axis slowest).
// Names are the values cut to folder names, unique within the sweep.
std::vector<Variant> expand_variants(const SweepSpec& spec);

// Writes each variant's values into the scene text (and a relative mesh path made absolute, so
// the variant's scene file reads from its own folder) and compiles it. A variant that does not
// compile is an error at its axis value's line, then the compiler's errors at the variant's scene
// file. False when any variant failed; nothing is written then.
bool build_variants(const SweepSpec& spec, const std::string& scene_text,
                    const std::filesystem::path& out_dir, std::vector<Variant>& variants,
                    DiagnosticEngine& diag);

// Writes out/<sweep>/sweep.json and each variant's scene.yaml and variant.json (only where they
// changed, so a rerun keeps what is done). False with `error` on a write failure.
bool write_variant_folders(const SweepSpec& spec, const std::vector<Variant>& variants,
                           const std::filesystem::path& out_dir, std::string* error);

// The sweep as written in sweep.json (what tasks and the result tables read).
nlohmann::json sweep_json(const SweepSpec& spec, const std::vector<Variant>& variants);

}  // namespace rigc::sweep
