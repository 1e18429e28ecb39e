// plslam: one binary, one subcommand per task. Exit codes: 0 success, 2 bad usage or
// bad input, 1 internal error.
#include <malloc.h>

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

namespace {

// Each frame allocates and frees buffers of image size (gradients, pyramids, the region grower's
// masks) and each keyframe the local BA's blocks. With glibc's defaults the threads' arenas give
// those pages back to the kernel and fault them in again next time: 226,000 page faults in a
// sequential run of the 300-frame street loop, 62,000 with this (3-4 % of its CPU time). Freed
// memory is kept for reuse instead, so resident memory stays near its peak: +7 MB on KITTI 06;
// on a 2000-frame street loop 220 MB after the loop's global BA instead of 173, flat in both.
// Under the sanitizers their own allocators replace glibc's, and this has no effect.
void keep_freed_memory_for_reuse() {
  mallopt(M_MMAP_THRESHOLD, 32 << 20);  // glibc's maximum: blocks up to 32 MB come from the arenas
  mallopt(M_TRIM_THRESHOLD, 1 << 30);   // return memory to the kernel only beyond 1 GB free
}

}  // namespace

int main(int argc, char** argv) {
  keep_freed_memory_for_reuse();
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
