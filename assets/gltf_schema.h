// The member types of a glTF file's JSON, checked before tinygltf reads it (internal to assets/).
#pragma once

#include <string>

namespace rigc::loading {

// tinygltf accepts many wrongly typed members by ignoring them (a "scene": "hello" silently
// becomes scene 0, a texture index of the wrong type drops the texture). This checks the types of
// the members RigC reads, and the required extensions; a LoadError names the first wrong member.
// A file whose JSON cannot be found or parsed passes: tinygltf then reports the problem.
void check_gltf_schema(const std::string& path, bool binary);

}  // namespace rigc::loading
