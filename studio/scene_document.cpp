#include "studio/scene_document.h"

#include <fmt/format.h>

#include "compiler/limits.h"
#include "io/atomic_file.h"
#include "io/file_status.h"

namespace rigc::studio {

namespace fs = std::filesystem;

bool SceneDocument::open(const fs::path& file, std::string* error) {
  file_ = file;
  disk_text_ = read_disk(error, &disk_identity_);
  if (!error->empty()) return false;
  opened_target_ = file_to_replace(file, error);
  return error->empty();
}

void SceneDocument::change_text(std::string text, Change change) {
  remember(std::move(text_), change);
  text_ = std::move(text);
}

void SceneDocument::undo_last_step() {
  text_ = std::move(undo_.back().text);
  undo_.pop_back();
}

void SceneDocument::remember(std::string text, Change change) {
  undo_.push_back({std::move(text), change});
  if (undo_.size() > kMostUndoSteps) undo_.pop_front();
}

std::string SceneDocument::read_disk(std::string* error, FileIdentity* identity) const {
  std::string why;
  auto file = read_bounded_file(file_, limits::kMostSceneFileBytes, &why);
  if (!file) {
    *error = fmt::format("rigc: error: cannot read {}: it {}\n", file_.string(), why);
    return {};
  }
  error->clear();
  *identity = file->identity;
  return std::move(file->bytes);
}

// Empty when file_ still leads to the file the session opened, that file is the one read or saved
// last and it holds what was read: otherwise why Save must not replace it.
std::string SceneDocument::changed_on_disk() const {
  std::string error;
  const fs::path target = file_to_replace(file_, &error);
  if (!error.empty()) return error;
  if (target != opened_target_) {
    return fmt::format("{} now leads to {}, not to the file the studio opened ({})", file_.string(),
                       target.string(), opened_target_.string());
  }
  if (names_nothing(target)) return "";  // deleted since: Save writes it anew
  FileIdentity identity;
  const std::string now = read_disk(&error, &identity);
  if (!error.empty()) return error;
  if (identity == disk_identity_ && now == disk_text_) return "";
  std::size_t line = 1, at = 0;
  while (at < now.size() && at < disk_text_.size() && now[at] == disk_text_[at]) {
    if (now[at++] == '\n') ++line;
  }
  const std::size_t start = now.rfind('\n', at == 0 ? 0 : at - 1);
  const std::size_t from = start == std::string::npos || at == 0 ? 0 : start + 1;
  const std::string now_line = now.substr(from, now.find('\n', from) - from);
  return fmt::format(
      "{} changed on disk since the studio read it (line {} now reads '{}'); the studio "
      "loads it on its next poll, then Save writes your changes over it",
      file_.string(), line, now_line.substr(0, 80));
}

bool SceneDocument::save(std::string* error) {
  if (const std::string changed = changed_on_disk(); !changed.empty()) {
    *error = "rigc: error: not saved: " + changed;
    return false;
  }
  if (!write_file_atomically(file_, text_, error)) {
    *error = "rigc: error: " + *error;
    return false;
  }
  disk_text_ = text_;
  if (const auto identity = identity_of(file_)) disk_identity_ = *identity;
  disk_error_.clear();
  file_error_.clear();
  return true;
}

std::optional<std::string> SceneDocument::poll_disk(bool* read_error_changed) {
  std::string error;
  FileIdentity identity;
  std::string text = read_disk(&error, &identity);
  *read_error_changed = error != disk_error_;
  disk_error_ = error;
  if (!error.empty()) return std::nullopt;
  disk_identity_ = identity;
  if (text == disk_text_) return std::nullopt;
  disk_text_ = text;
  return text;
}

void SceneDocument::reloaded(const std::string& text, bool applied, std::string compile_error) {
  file_error_ = applied ? "" : std::move(compile_error);
  ++reloads_;
  if (applied && text != text_) change_text(text, Change::kAnything);
}

}  // namespace rigc::studio
