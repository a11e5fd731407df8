#include "cli/commands.h"
#include "io/allocator.h"

int main(int argc, char** argv) {
  rigc::keep_freed_memory();
  return rigc::cli::run_main(std::vector<std::string>(argv, argv + argc));
}
