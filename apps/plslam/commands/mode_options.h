#pragma once
// The pipeline mode flags shared by `plslam run` and `plslam bench slam` (which passes them on to
// its runs): the default deterministic pipeline, --sequential or --free-running.
#include <string>

#include <CLI/CLI.hpp>

namespace plslam::cli {

struct ModeArgs {
  bool sequential = false;
  bool deterministic = false;  // the default; the flag is kept so that older command lines still run
  bool free_running = false;

  // The name stats.json and report.json give the mode.
  const char* name() const { return sequential ? "sequential" : free_running ? "free-running" : "deterministic"; }
  // The flag that selects it in `plslam run`; empty for the default.
  std::string run_flag() const { return sequential ? "--sequential" : free_running ? "--free-running" : ""; }
};

// The three flags, each excluding the others (exit 2 on a pair).
inline void add_mode_flags(CLI::App& sub, ModeArgs& m, const std::string& sequential_help,
                           const std::string& deterministic_help, const std::string& free_running_help) {
  auto* sequential = sub.add_flag("--sequential", m.sequential, sequential_help);
  auto* deterministic = sub.add_flag("--deterministic", m.deterministic, deterministic_help)->excludes(sequential);
  sub.add_flag("--free-running", m.free_running, free_running_help)->excludes(sequential)->excludes(deterministic);
}

}  // namespace plslam::cli
