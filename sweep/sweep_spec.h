// The sweep file (`rigc-sweep: 1`) and `--vary PATH=V1,V2,...`: a scene, the values to vary in it
// (axes, combined as a grid unless `zip:` pairs them), the backend (possibly an axis), the render
// scale, the ray tracers' samples and what to measure.
#pragma once

#include <optional>
#include <string>
#include <vector>

#include "compiler/diagnostics.h"

namespace rigc::sweep {

struct AxisValue {
  std::string text;
  SourceLoc loc;  // in the sweep file (the command line for --vary: no line)
};

struct Axis {
  std::string path;  // into the scene (`camera.exposure.aperture`), or "backend"
  SourceLoc loc;
  std::vector<AxisValue> values;
  bool is_backend() const { return path == "backend"; }
};

struct SweepSpec {
  std::string file;        // the sweep file; empty for --vary on the command line
  std::string name;        // names the output folder out/<name>/
  std::string scene_path;  // as given, resolved against the sweep file's folder
  std::vector<Axis> axes;
  std::vector<std::vector<int>> zip_groups;  // axes (indices) paired value by value
  std::string backend = "preview";           // when the backend is no axis
  double scale = 0.25;
  // Every backend's samples per pixel; 0 = each backend's default; run::kConvergedSamples.
  int samples = 0;
  bool coverage = true, eval = false;
};

// Reads a sweep file; reports every problem at its line and returns nullopt if there was any.
std::optional<SweepSpec> read_sweep_file(const std::string& path, DiagnosticEngine& diag);
std::optional<SweepSpec> parse_sweep_text(const std::string& text, const std::string& file,
                                          DiagnosticEngine& diag);

// One `--vary PATH=V1,V2,...` axis; nullopt with `error` when it is malformed.
std::optional<Axis> parse_vary_option(const std::string& text, std::string* error);

// `text` cut down to a folder name: letters, digits, '.', '+' and '-' kept, the rest '-', at most
// `max_size` bytes, never empty, '.' or '..'.
std::string folder_name(const std::string& text, std::size_t max_size = 40);

// Every problem with the axes themselves (a path given twice, an empty axis, zipped axes of
// different lengths, an unknown backend), reported at their lines.
bool check_axes(const SweepSpec& spec, DiagnosticEngine& diag);

}  // namespace rigc::sweep
