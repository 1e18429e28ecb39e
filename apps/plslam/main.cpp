// plslam: one binary, one subcommand per task. Exit codes: 0 success, 2 bad usage or
// bad input, 1 internal error.
#include <algorithm>
#include <exception>
#include <iostream>
#include <map>
#include <string_view>

#include "command_registry.h"
#include "json_stdout.h"
#include "plslam/core/error.h"
#include "plslam/core/log.h"
#include "plslam/core/version.h"

int main(int argc, char** argv) {
  CLI::App app{"plslam: stereo visual SLAM with points and lines"};
  app.set_version_flag("--version", std::string("plslam ") + plslam::kVersion);
  app.require_subcommand(1);
  bool verbose = false;
  app.add_flag("-v,--verbose", verbose, "Debug logging");

  auto& commands = plslam::cli::command_list();
  std::sort(commands.begin(), commands.end(),
            [](const auto& a, const auto& b) { return a.name < b.name; });
  std::map<CLI::App*, std::function<int()>> actions;
  for (const auto& c : commands) {
    CLI::App* sub = app.add_subcommand(c.name, c.description);
    actions[sub] = c.setup(*sub);
  }

  try {
    app.parse(argc, argv);
  } catch (const CLI::ParseError& e) {
    const int code = app.exit(e);
    // CLI11 returns 0 for --help/--version and its own codes for errors; usage errors are 2.
    return code == 0 ? 0 : 2;
  }

  plslam::init_logging(verbose ? plslam::LogLevel::kDebug : plslam::LogLevel::kInfo);
  try {
    if (std::any_of(argv + 1, argv + argc, [](const char* a) { return std::string_view(a) == "--json"; })) {
      plslam::cli::reserve_stdout_for_json();
    }
    for (auto* sub : app.get_subcommands()) return actions.at(sub)();
    return 2;
  } catch (const plslam::InputError& e) {
    std::cerr << "plslam: error: " << e.what() << "\n";
    return 2;
  } catch (const std::exception& e) {
    std::cerr << "plslam: internal error: " << e.what() << "\n";
    return 1;
  }
}
