// The trajectory readers of `plslam eval` (TUM, KITTI, EuRoC csv) and the format detection. The
// first byte chooses the format; the rest is the file.
#include "fuzz/targets/fuzz_support.h"
#include "plslam/io/trajectory_io.h"

namespace plslam::fuzz {

int fuzz_trajectory(const std::uint8_t* data, std::size_t size) {
  if (size == 0) return 0;
  static const char* kNames[] = {"traj.tum", "traj.kitti", "traj.csv", "traj.txt"};
  const auto path = scratch_dir() / kNames[data[0] % 4];
  write_file(path, as_string(data + 1, size - 1));
  return expect_only_input_errors("trajectory", [&] {
    const io::TrajectoryFormat format = data[0] % 4 == 3 ? io::detect_trajectory_format(path)
                                        : data[0] % 4 == 0 ? io::TrajectoryFormat::kTum
                                        : data[0] % 4 == 1 ? io::TrajectoryFormat::kKitti
                                                           : io::TrajectoryFormat::kEuroc;
    const std::vector<double> times{0.0, 0.1, 0.2};
    const bool with_times = format == io::TrajectoryFormat::kKitti && (data[0] & 0x10);
    (void)io::read_trajectory(path, format, with_times ? &times : nullptr,
                              data[0] & 0x20 ? io::KittiRotation::kAsWritten : io::KittiRotation::kNearestRotation);
  });
}

}  // namespace plslam::fuzz
