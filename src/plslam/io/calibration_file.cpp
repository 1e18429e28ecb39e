#include "plslam/io/calibration_file.h"

#include "plslam/core/config_reader.h"

namespace plslam::io {
StereoCalibration read_calibration_file(const std::filesystem::path& path) {
  const auto config = ConfigReader::from_file(path);
  StereoCalibration c;
  config.get("width", c.width);
  config.get("height", c.height);
  config.get("fx", c.fx);
  config.get("fy", c.fy);
  config.get("cx", c.cx);
  config.get("cy", c.cy);
  config.get("baseline", c.baseline);
  config.check_all_used();
  return c;
}
}  // namespace plslam::io
