#include "plslam/io/imu_input.h"

#include <algorithm>
#include <cmath>

#include <fmt/format.h>
#include <spdlog/spdlog.h>

#include "plslam/core/error.h"
#include "plslam/io/imu_csv.h"
#include "plslam/io/imu_sensor.h"

namespace plslam::io {

ImuData read_imu(const std::filesystem::path& csv, const std::filesystem::path& yaml,
                 const Eigen::Isometry3d& T_body_cam) {
  ImuData imu;
  imu.calibration = read_imu_sensor_yaml(yaml);
  imu.samples = read_imu_csv(csv);
  imu.T_imu_cam = imu.calibration.T_BS.inverse() * T_body_cam;
  const double measured = median_rate_hz(imu.samples);
  if (std::abs(measured - imu.calibration.rate_hz) > 0.1 * imu.calibration.rate_hz) {
    spdlog::warn("{}: samples come at {:.4g} Hz, but {} says rate_hz {:.4g}", csv.string(), measured, yaml.string(),
                 imu.calibration.rate_hz);
  }
  return imu;
}

void keep_imu_span(ImuData& imu, double t_first, double t_last, const std::filesystem::path& csv) {
  auto& s = imu.samples;
  if (s.empty() || s.front().t > t_first || s.back().t < t_last) {
    throw InputError(csv.string(),
                     s.empty() ? std::string("no IMU samples")
                               : fmt::format("the IMU samples from {:.6f} s to {:.6f} s do not cover the frames from "
                                             "{:.6f} s to {:.6f} s (the same clock)",
                                             s.front().t, s.back().t, t_first, t_last));
  }
  const auto begin = std::lower_bound(s.begin(), s.end(), t_first - kImuMarginS,
                                      [](const ImuSample& a, double t) { return a.t < t; });
  const auto end = std::upper_bound(begin, s.end(), t_last + kImuMarginS,
                                    [](double t, const ImuSample& a) { return t < a.t; });
  s = std::vector<ImuSample>(begin, end);
}

double median_rate_hz(const std::vector<ImuSample>& samples) {
  if (samples.size() < 2) return 0.0;
  std::vector<double> dt(samples.size() - 1);
  for (std::size_t i = 1; i < samples.size(); ++i) dt[i - 1] = samples[i].t - samples[i - 1].t;
  std::nth_element(dt.begin(), dt.begin() + static_cast<std::ptrdiff_t>(dt.size() / 2), dt.end());
  const double median = dt[dt.size() / 2];
  return median > 0 ? 1.0 / median : 0.0;
}

}  // namespace plslam::io
