#include "compiler/diagnostics.h"

#include <algorithm>
#include <iostream>
#include <sstream>
#include <utility>

#include "ir/utf8_text.h"

namespace rigc {
namespace {

// A long source line cut to the part around column `col` (1-based, 0 for none), with "..." where
// it was cut, and the column within that part: a minified or generated line can be megabytes.
std::pair<std::string, int> line_around(const std::string& line, int col) {
  constexpr int kMostShown = 120;
  if (static_cast<int>(line.size()) <= kMostShown) return {line, col};
  const int first =
      std::clamp(col - 1 - kMostShown / 2, 0, static_cast<int>(line.size()) - kMostShown);
  std::string part = line.substr(first, kMostShown);
  int shown_col = col > 0 ? col - first : 0;
  if (first > 0) {
    part = "..." + part;
    if (shown_col > 0) shown_col += 3;
  }
  if (first + kMostShown < static_cast<int>(line.size())) part += "...";
  return {part, shown_col};
}

}  // namespace

DiagnosticEngine::DiagnosticEngine()
    : handler_([](const Diagnostic&, const std::string& rendered) { std::cerr << rendered; }) {}

void DiagnosticEngine::add_source(const std::string& file, std::string text) {
  std::vector<std::string> lines;
  std::istringstream stream(text);
  std::string line;
  while (std::getline(stream, line)) {
    if (!line.empty() && line.back() == '\r') line.pop_back();
    lines.push_back(line);
  }
  source_lines_[valid_utf8_text(file)] = std::move(lines);
}

void DiagnosticEngine::error(const SourceLoc& loc, std::string message) {
  report({Severity::kError, loc, std::move(message)});
}
void DiagnosticEngine::warning(const SourceLoc& loc, std::string message) {
  report({Severity::kWarning, loc, std::move(message)});
}
void DiagnosticEngine::note(const SourceLoc& loc, std::string message) {
  report({Severity::kNote, loc, std::move(message)});
}

void DiagnosticEngine::report(Diagnostic diagnostic) {
  // Messages quote file and material names, which may hold any bytes; diagnostics are also JSON.
  diagnostic.loc.file = valid_utf8_text(diagnostic.loc.file);
  diagnostic.message = valid_utf8_text(diagnostic.message);
  if (diagnostic.severity == Severity::kError) ++error_count_;
  if (diagnostic.severity == Severity::kWarning) ++warning_count_;
  diagnostics_.push_back(diagnostic);
  if (handler_) handler_(diagnostics_.back(), render(diagnostics_.back()));
}

std::string DiagnosticEngine::render(const Diagnostic& d) const {
  std::ostringstream out;
  out << (d.loc.file.empty() ? std::string("rigc") : d.loc.file);
  if (d.loc.line > 0) {
    out << ':' << d.loc.line;
    if (d.loc.col > 0) out << ':' << d.loc.col;
  }
  switch (d.severity) {
    case Severity::kError:
      out << ": error: ";
      break;
    case Severity::kWarning:
      out << ": warning: ";
      break;
    case Severity::kNote:
      out << ": note: ";
      break;
  }
  out << d.message << '\n';
  auto it = source_lines_.find(d.loc.file);
  if (it != source_lines_.end() && d.loc.line > 0 &&
      d.loc.line <= static_cast<int>(it->second.size())) {
    const auto [line, col] = line_around(it->second[d.loc.line - 1], d.loc.col);
    out << "  " << line << '\n';
    if (col > 0) {
      std::string pad;
      // Keep tabs so the caret lines up under the same column in a terminal.
      for (int i = 0; i < col - 1 && i < static_cast<int>(line.size()); ++i) {
        pad += line[i] == '\t' ? '\t' : ' ';
      }
      out << "  " << pad << "^\n";
    }
  }
  return out.str();
}

int edit_distance(const std::string& a, const std::string& b) {
  std::vector<int> previous(b.size() + 1), current(b.size() + 1);
  for (size_t j = 0; j <= b.size(); ++j) previous[j] = static_cast<int>(j);
  for (size_t i = 1; i <= a.size(); ++i) {
    current[0] = static_cast<int>(i);
    for (size_t j = 1; j <= b.size(); ++j) {
      int substitution = previous[j - 1] + (a[i - 1] == b[j - 1] ? 0 : 1);
      current[j] = std::min({previous[j] + 1, current[j - 1] + 1, substitution});
    }
    std::swap(previous, current);
  }
  return previous[b.size()];
}

std::string closest_match(const std::string& word, const std::vector<std::string>& candidates) {
  std::string best;
  int best_distance = 1 << 30;
  for (const auto& candidate : candidates) {
    int distance = edit_distance(word, candidate);
    if (distance < best_distance) {
      best_distance = distance;
      best = candidate;
    }
  }
  // Allow roughly one typo per three letters, at least two.
  int limit = std::max(2, static_cast<int>(word.size()) / 3);
  return best_distance <= limit ? best : std::string();
}

}  // namespace rigc
