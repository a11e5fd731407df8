// The files a command reads (the scene, its mesh, MTL libraries, textures): no writer of rigc
// replaces or deletes one, however its path is spelled (relative, through a symbolic link, or a
// hard link: files are compared by device and inode).
#pragma once

#include <filesystem>
#include <optional>
#include <string>
#include <vector>

namespace rigc {

// Turns the protection on: rigc's main() does, so that a library call (eval's input checks, in
// the test binary too) records nothing for a process that did not ask.
void enable_input_protection();

// Records the file at `path` (following symbolic links), if there is one and protection is on, as
// an input; `what` names it in messages ("the scene's mesh"). Thread-safe.
void protect_input_file(const std::filesystem::path& path, const std::string& what);

// Records the folder `dir` as an input (photos, masks made elsewhere): a folder the command
// clears must not hold it.
void protect_input_folder(const std::filesystem::path& dir, const std::string& what);

// "WHAT (PATH)" for the first recorded input or input folder that is `dir` or lies under it
// (symbolic links resolved), for a command about to clear `dir`.
std::optional<std::string> protected_input_within(const std::filesystem::path& dir);

// What the file at `path` (following symbolic links) is when it is a recorded input, for
// "cannot write PATH: it is WHAT, an input of this command".
std::optional<std::string> protected_input_at(const std::filesystem::path& path);

// The material libraries an OBJ file names on its `mtllib` lines, resolved against its folder.
// Empty for another format or an unreadable file.
std::vector<std::filesystem::path> obj_material_libraries(const std::filesystem::path& obj);

}  // namespace rigc
