#include "plslam/core/log.h"

#include <spdlog/sinks/stdout_color_sinks.h>

namespace plslam {

void init_logging(LogLevel level) {
  static auto logger = [] {
    auto l = spdlog::stderr_color_mt("plslam");
    l->set_pattern("[%^%l%$] %v");
    spdlog::set_default_logger(l);
    return l;
  }();
  switch (level) {
    case LogLevel::kQuiet: logger->set_level(spdlog::level::warn); break;
    case LogLevel::kInfo: logger->set_level(spdlog::level::info); break;
    case LogLevel::kDebug: logger->set_level(spdlog::level::debug); break;
  }
}

}  // namespace plslam
