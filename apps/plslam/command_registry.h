#pragma once
// Subcommands register themselves from apps/plslam/commands/*.cpp with a static
// CommandRegistration, so adding a command touches no shared file.
#include <CLI/CLI.hpp>

#include <functional>
#include <string>
#include <vector>

namespace plslam::cli {

// Builds the subcommand's options on `sub` and returns the action to run when it is chosen.
// The action returns the process exit code.
using CommandSetup = std::function<std::function<int()>(CLI::App& sub)>;

struct Command {
  std::string name;
  std::string description;
  CommandSetup setup;
};

std::vector<Command>& command_list();

struct CommandRegistration {
  explicit CommandRegistration(Command c) { command_list().push_back(std::move(c)); }
};

}  // namespace plslam::cli
