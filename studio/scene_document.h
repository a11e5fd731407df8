// The scene file as the studio edits it: the text as the user changed it, the undo steps, and
// the file on disk (read, saved, watched for changes made elsewhere). Not thread-safe: the
// session (studio/session.h) holds its lock around every call.
#pragma once

#include <cstddef>
#include <deque>
#include <filesystem>
#include <optional>
#include <string>

#include "io/bounded_file.h"

namespace rigc::studio {

// What a change of the scene text touched, so that what it cannot have changed is kept: the
// prepared studio (object, materials, studio) across camera and shot changes, the view across
// shot changes, the coverage across shot changes (captures and their undo).
enum class Change { kAnything, kCamera, kShots };

// A text to go back to, and what going back changes.
struct UndoStep {
  std::string text;
  Change change;
};

class SceneDocument {
 public:
  // Reads `file` (bounded like the compiler's reads); false with `error` ("rigc: error: ...").
  bool open(const std::filesystem::path& file, std::string* error);

  const std::filesystem::path& file() const { return file_; }
  const std::string& text() const { return text_; }            // the scene as the user changed it
  const std::string& disk_text() const { return disk_text_; }  // the file as read or saved last
  bool unsaved() const { return text_ != disk_text_; }
  // The text becomes `text` (it compiled); the one before it is kept as an undo step.
  void change_text(std::string text, Change change);
  // The text becomes `text` without an undo step (the file read at open).
  void set_text(std::string text) { text_ = std::move(text); }

  bool can_undo() const { return !undo_.empty(); }
  const UndoStep& last_step() const { return undo_.back(); }
  // The last step was undone: its text is the document's now.
  void undo_last_step();

  // Writes the text over the file the session opened, atomically; false with `error` when the
  // file changed on disk since it was read (or its link leads elsewhere) or cannot be written.
  bool save(std::string* error);
  // The file's text when it changed on disk since it was read or saved (the caller compiles and
  // applies it, then calls reloaded), else nullopt. `read_error_changed`: the file could or could
  // not be read where at the last poll it was the other way.
  std::optional<std::string> poll_disk(bool* read_error_changed);
  // The text read by poll_disk was applied (`compile_error` empty) or does not compile.
  void reloaded(const std::string& text, bool applied, std::string compile_error);

  // Why the file on disk cannot be read or does not compile ("" when it can and does).
  const std::string& file_error() const { return disk_error_.empty() ? file_error_ : disk_error_; }
  int reloads() const { return reloads_; }  // the file's changes on disk, made elsewhere

 private:
  std::string read_disk(std::string* error, FileIdentity* identity) const;
  std::string changed_on_disk() const;
  void remember(std::string text, Change change);

  std::filesystem::path file_;
  std::string disk_text_;  // the file as last read or saved
  // The file read or saved last, and the one file_ led to when the session opened (through a
  // symbolic link, if file_ is one): Save replaces that file and no other.
  FileIdentity disk_identity_;
  std::filesystem::path opened_target_;
  std::string disk_error_;  // why the file could not be read at the last poll
  std::string file_error_;  // the file on disk does not compile: its diagnostics
  std::string text_;
  // The last kMostUndoSteps changes: an hour of slider turns would otherwise keep every text.
  static constexpr std::size_t kMostUndoSteps = 500;
  std::deque<UndoStep> undo_;
  int reloads_ = 0;
};

}  // namespace rigc::studio
