#include "cli/commands.h"
#include "cli/standard_streams.h"
#include "io/allocator.h"

int main(int argc, char** argv) {
  rigc::cli::guard_standard_streams();
  rigc::keep_freed_memory();
  const int code = rigc::cli::run_main(std::vector<std::string>(argv, argv + argc));
  return rigc::cli::finish_standard_output(code);
}
