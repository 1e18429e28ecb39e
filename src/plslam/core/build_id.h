#pragma once
// Which build of plslam is running: the linker's GNU build id of the program (a hash of the linked
// output, `readelf -n`), so that results collected from many machines can be checked to come from
// the same binary, and the host it runs on.
#include <string>

namespace plslam {

// The running program's GNU build id in hex, or "unknown" when it was linked without one.
std::string build_id();

// This machine's host name ("unknown" when it cannot be read).
std::string host_name();

}  // namespace plslam
