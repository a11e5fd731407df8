// Output paths beyond one file: the folders outputs go into, and the temporaries of atomic writes
// (io/atomic_file.h) that a killed writer leaves behind.
#pragma once

#include <filesystem>
#include <string>

namespace rigc {

// True for a name temporary_path_beside makes ('.shot_000.jpg.tmp.4242.7.1a2b3c'): a file a
// crashed or killed writer left behind.
bool is_temporary_name(const std::string& filename);

// Removes from `dir` (not its subfolders) the temporaries whose writer is no longer running on
// this machine: what an interrupted run left behind, safe beside a writer still at work. The
// number removed.
int remove_abandoned_temporaries(const std::filesystem::path& dir);

// Creates the folder `dir` and its parents unless it is there. False with one line in `error` (if
// not null) naming `dir` and why: a symbolic link that loops or leads nowhere, a file in the way,
// no permission. Never throws.
bool make_output_folder(const std::filesystem::path& dir, std::string* error);

// Empties the folder `dir` (a command's own work folder, rewritten each run) and makes it anew.
// Refuses, touching nothing, when `dir` is or holds an input of this command
// (io/input_files.h): `-o OUT --masks OUT/masks` must not delete the masks it is about to read.
bool clear_output_folder(const std::filesystem::path& dir, std::string* error);

}  // namespace rigc
