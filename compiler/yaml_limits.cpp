#include "compiler/yaml_limits.h"

#include <fmt/format.h>
#include <yaml-cpp/eventhandler.h>
#include <yaml-cpp/mark.h>
#include <yaml-cpp/parser.h>

#include <map>
#include <set>
#include <sstream>
#include <vector>

namespace rigc {
namespace {

// Thrown from inside yaml-cpp's parse to stop it at the first problem.
struct ShapeError {
  YamlShapeProblem problem;
};

// Counts each node, and each alias as the nodes of its anchor, so the count is the size of the
// document with its aliases written out.
class ShapeCounter final : public YAML::EventHandler {
 public:
  void OnDocumentStart(const YAML::Mark&) override {
    open_.clear();
    sizes_.clear();
    total_ = 0;
  }
  void OnDocumentEnd() override {}
  void OnNull(const YAML::Mark& mark, YAML::anchor_t anchor) override { leaf(mark, anchor); }
  void OnScalar(const YAML::Mark& mark, const std::string&, YAML::anchor_t anchor,
                const std::string&) override {
    leaf(mark, anchor);
  }
  void OnAlias(const YAML::Mark& mark, YAML::anchor_t anchor) override {
    for (const auto& collection : open_) {
      if (collection.anchor == anchor) {
        fail(mark, "this alias refers to a list or map that holds it: the value would never end");
      }
    }
    const auto size = sizes_.find(anchor);
    add(mark, size == sizes_.end() ? 1 : size->second);
  }
  void OnSequenceStart(const YAML::Mark& mark, const std::string&, YAML::anchor_t anchor,
                       YAML::EmitterStyle::value) override {
    open(mark, anchor);
  }
  void OnSequenceEnd() override { close(); }
  void OnMapStart(const YAML::Mark& mark, const std::string&, YAML::anchor_t anchor,
                  YAML::EmitterStyle::value) override {
    open(mark, anchor);
  }
  void OnMapEnd() override { close(); }

 private:
  struct Open {
    YAML::anchor_t anchor;
    std::size_t nodes;  // within it so far, aliases written out
  };

  [[noreturn]] static void fail(const YAML::Mark& mark, std::string message) {
    throw ShapeError{{mark.line, mark.column, std::move(message)}};
  }

  void add(const YAML::Mark& mark, std::size_t nodes) {
    total_ += nodes;
    if (total_ > kMostYamlNodes) {
      fail(mark, fmt::format("the file holds more than {} values once its aliases are written "
                             "out (aliases that repeat aliases multiply)",
                             kMostYamlNodes));
    }
    if (!open_.empty()) open_.back().nodes += nodes;
  }
  void leaf(const YAML::Mark& mark, YAML::anchor_t anchor) {
    add(mark, 1);
    if (anchor != YAML::NullAnchor) sizes_[anchor] = 1;
  }
  void open(const YAML::Mark& mark, YAML::anchor_t anchor) {
    if (static_cast<int>(open_.size()) >= kMostYamlDepth) {
      fail(mark, fmt::format("lists and maps nest deeper than {} levels here", kMostYamlDepth));
    }
    add(mark, 1);
    open_.push_back({anchor, 1});
  }
  void close() {
    const Open done = open_.back();
    open_.pop_back();
    if (done.anchor != YAML::NullAnchor) sizes_[done.anchor] = done.nodes;
    // The parent counted the collection itself when it opened; now its contents.
    if (!open_.empty()) open_.back().nodes += done.nodes - 1;
  }

  std::vector<Open> open_;
  std::map<YAML::anchor_t, std::size_t> sizes_;
  std::size_t total_ = 0;
};

}  // namespace

std::optional<YamlShapeProblem> yaml_shape_problem(const std::string& text) {
  std::istringstream in(text);
  YAML::Parser parser(in);
  ShapeCounter counter;
  try {
    // Two documents at most: a scene holds one, and yaml-cpp can report empty documents forever
    // (a lone ',' at the top level).
    for (int documents = 0; documents < 2 && parser.HandleNextDocument(counter); ++documents) {
    }
  } catch (const ShapeError& e) {
    return e.problem;
  }
  return std::nullopt;
}

}  // namespace rigc
