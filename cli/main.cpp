#include "cli/commands.h"
#include "cli/standard_streams.h"
#include "io/allocator.h"
#include "io/input_files.h"

int main(int argc, char** argv) {
  rigc::cli::guard_standard_streams();
  rigc::keep_freed_memory();
  rigc::enable_input_protection();
  const int code = rigc::cli::run_main(std::vector<std::string>(argv, argv + argc));
  return rigc::cli::finish_standard_output(code);
}
