// The stereo calibration file of video and camera input (io/calibration_file.h).
#include "fuzz/targets/fuzz_support.h"
#include "plslam/io/calibration_file.h"

namespace plslam::fuzz {

int fuzz_calibration_file(const std::uint8_t* data, std::size_t size) {
  const auto path = scratch_dir() / "calibration.yaml";
  write_file(path, as_string(data, size));
  return expect_only_input_errors("calibration_file", [&] { (void)io::read_calibration_file(path); });
}

}  // namespace plslam::fuzz
