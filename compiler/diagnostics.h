// Compiler-style diagnostics: `file:line:col: severity: message`, the source line and a caret.
#pragma once

#include <functional>
#include <map>
#include <string>
#include <vector>

#include "ir/source_location.h"

namespace rigc {

enum class Severity { kNote, kWarning, kError };

struct Diagnostic {
  Severity severity = Severity::kError;
  SourceLoc loc;
  std::string message;
};

// Collects diagnostics; renders them with the offending source line. Tests install a handler to
// capture them instead of printing.
class DiagnosticEngine {
 public:
  using Handler = std::function<void(const Diagnostic&, const std::string& rendered)>;

  DiagnosticEngine();
  void set_handler(Handler handler) { handler_ = std::move(handler); }
  // Registers a file's text so that diagnostics in it can show the line.
  void add_source(const std::string& file, std::string text);

  void error(const SourceLoc& loc, std::string message);
  void warning(const SourceLoc& loc, std::string message);
  void note(const SourceLoc& loc, std::string message);
  void report(Diagnostic diagnostic);

  int error_count() const { return error_count_; }
  int warning_count() const { return warning_count_; }
  bool has_errors() const { return error_count_ > 0; }
  const std::vector<Diagnostic>& diagnostics() const { return diagnostics_; }

  // `file:line:col: error: msg` + the source line + a caret (no colour).
  std::string render(const Diagnostic& diagnostic) const;

 private:
  Handler handler_;
  std::map<std::string, std::vector<std::string>> source_lines_;
  std::vector<Diagnostic> diagnostics_;
  int error_count_ = 0;
  int warning_count_ = 0;
};

// Edit distance, for "did you mean" suggestions.
int edit_distance(const std::string& a, const std::string& b);
// The closest candidate within a small distance, or "" if none is close.
std::string closest_match(const std::string& word, const std::vector<std::string>& candidates);

}  // namespace rigc
