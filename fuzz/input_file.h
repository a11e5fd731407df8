// What the fuzz entry points share: the readers that want a file get the input written to one.
#pragma once

#include <filesystem>
#include <optional>
#include <stdexcept>
#include <string>
#include <string_view>

namespace rigc::fuzz {

// A folder of this process's own (under TMPDIR), removed at exit.
const std::filesystem::path& input_dir();

// Writes `input` to the file `name` in input_dir() and returns its path.
std::filesystem::path write_input(std::string_view input, const std::string& name);

// A reader's failure must come with a message.
template <typename Result>
void require_error_if_failed(const std::optional<Result>& result, const std::string& error) {
  if (!result && error.empty()) throw std::logic_error("a reader failed without an error");
}

}  // namespace rigc::fuzz
