// The IMU's two files: the sample file (EuRoC's imu0/data.csv, --imu) and its sensor.yaml
// (imu0/sensor.yaml, --imu-calib). Samples that parse are then cut to a span of frames, as the
// readers do.
#include "fuzz/targets/fuzz_support.h"
#include "plslam/io/imu_csv.h"
#include "plslam/io/imu_input.h"
#include "plslam/io/imu_sensor.h"

namespace plslam::fuzz {

int fuzz_imu_csv(const std::uint8_t* data, std::size_t size) {
  const auto path = scratch_dir() / "imu.csv";
  write_file(path, as_string(data, size));
  return expect_only_input_errors("imu_csv", [&] {
    ImuData imu;
    imu.samples = io::read_imu_csv(path);
    (void)io::median_rate_hz(imu.samples);
    // Frames in the middle of the samples' span: a span they cover.
    const double t0 = imu.samples.front().t, t1 = imu.samples.back().t;
    io::keep_imu_span(imu, t0 + 0.25 * (t1 - t0), t0 + 0.75 * (t1 - t0), path);
  });
}

int fuzz_imu_sensor(const std::uint8_t* data, std::size_t size) {
  const auto path = scratch_dir() / "imu_sensor.yaml";
  write_file(path, as_string(data, size));
  return expect_only_input_errors("imu_sensor", [&] { (void)io::read_imu_sensor_yaml(path); });
}

}  // namespace plslam::fuzz
