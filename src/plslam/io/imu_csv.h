#pragma once
// The IMU sample file in EuRoC's imu0/data.csv layout, also the --imu file of video and camera
// input: one sample per line, "timestamp [ns], gyro x, y, z [rad/s], acc x, y, z [m/s^2]",
// comma-separated. Lines starting with '#', blank lines and a first line of column names are
// skipped; CRLF line ends and a UTF-8 byte-order mark are accepted.
#include <cstddef>
#include <filesystem>
#include <vector>

#include "plslam/core/imu.h"

namespace plslam::io {

// A pause between two samples longer than this many median sample periods is an error: the IMU
// dropped data there, and integrating across the hole would invent the motion in it. EuRoC's
// periods vary by well under 1 %.
inline constexpr double kMaxImuGapPeriods = 5.0;

// Fewer samples do not make one sample period.
inline constexpr std::size_t kMinImuSamples = 2;

// The samples in file order, t = ns * 1e-9 (as the EuRoC reader converts image timestamps).
// Throws InputError naming the file (and the line) for a missing file, a line without 7 columns,
// a field that is not a number (whole nanoseconds for the timestamp), NaN or infinity, a timestamp
// not after the previous one (a duplicate, or going back), a gap over kMaxImuGapPeriods median
// periods, or fewer than kMinImuSamples samples. A last line cut short without its line end (a
// copy or recording stopped mid-line) is left out with a warning.
std::vector<ImuSample> read_imu_csv(const std::filesystem::path& path);

}  // namespace plslam::io
