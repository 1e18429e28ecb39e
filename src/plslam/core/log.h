#pragma once
// Thin logging front: spdlog with a short pattern, to stderr so stdout stays parseable (--json).
#include <spdlog/spdlog.h>

namespace plslam {

enum class LogLevel { kQuiet, kInfo, kDebug };

// Sets up the default logger once; safe to call again to change the level.
void init_logging(LogLevel level);

}  // namespace plslam
