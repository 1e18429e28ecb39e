#pragma once

namespace plslam {
inline constexpr const char* kVersion = PLSLAM_VERSION;
}  // namespace plslam
