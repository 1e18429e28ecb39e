#pragma once
// Runs another program to completion with its output in a log file. `plslam bench slam` runs
// every SLAM run in a process of its own, so that runs cannot share state (heap layout, caches,
// a crash) and an external anchor runs exactly like plslam does.
#include <filesystem>
#include <functional>
#include <string>
#include <vector>

namespace plslam {

// Starts argv[0] (searched in PATH when it has no slash) with stdout and stderr appended to
// `log`, in a process group of its own so that a Ctrl-C at the terminal reaches only this
// process. While it runs, `stop` is polled: the first time it returns true the child gets one
// SIGTERM (it then stops at a frame boundary and writes its outputs). Returns the exit code, or
// 128 + the signal number when the child was killed by a signal. Throws InputError naming argv[0]
// when it cannot be started, or `log` when the log cannot be opened.
int run_process(const std::vector<std::string>& argv, const std::filesystem::path& log,
                const std::function<bool()>& stop = {});

// The running executable's own path (/proc/self/exe).
std::filesystem::path current_executable();

}  // namespace plslam
