// The stereo calibration file of --calib (io/calibration_file.h): the rectified form, and the raw
// cameras' camchain form (io/camchain_file.h) that plslam calibrate writes.
#include "fuzz/targets/fuzz_support.h"
#include "plslam/io/calibration_file.h"

namespace plslam::fuzz {

int fuzz_calibration_file(const std::uint8_t* data, std::size_t size) {
  const auto path = scratch_dir() / "calibration.yaml";
  write_file(path, as_string(data, size));
  return expect_only_input_errors("calibration_file", [&] { (void)io::read_user_calibration(path); });
}

}  // namespace plslam::fuzz
