// EuRoC cam0/sensor.yaml: intrinsics, distortion, resolution, rate and T_BS.
#include "fuzz/targets/fuzz_support.h"
#include "plslam/io/euroc_sensor.h"

namespace plslam::fuzz {

int fuzz_euroc_sensor(const std::uint8_t* data, std::size_t size) {
  const auto path = scratch_dir() / "sensor.yaml";
  write_file(path, as_string(data, size));
  return expect_only_input_errors("euroc_sensor", [&] {
    (void)io::read_euroc_camera_yaml(path);
    (void)io::read_euroc_T_BS(path);
  });
}

}  // namespace plslam::fuzz
