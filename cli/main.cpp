#include "cli/commands.h"

int main(int argc, char** argv) {
  return rigc::cli::run_main(std::vector<std::string>(argv, argv + argc));
}
