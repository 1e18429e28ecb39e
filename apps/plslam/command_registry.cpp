#include "command_registry.h"

namespace plslam::cli {

std::vector<Command>& command_list() {
  static std::vector<Command> commands;
  return commands;
}

}  // namespace plslam::cli
