#include "plslam/system/imu_init_monitor.h"

#include <fmt/format.h>

namespace plslam::system {

ImuInitMonitor::ImuInitMonitor(const ImuData& imu, ImuInitMonitorOptions options) : imu_(imu), options_(options) {
  options_.init.validate();
}

void ImuInitMonitor::add(double timestamp, const std::optional<Eigen::Isometry3d>& T_world_camera) {
  if (accepted_) return;
  if (!T_world_camera) {
    window_.clear();
    return;
  }
  if (!window_.empty() && timestamp - window_.back().t < options_.min_frame_spacing_s) return;
  window_.push_back({timestamp, *T_world_camera});
  while (window_.back().t - window_.front().t > options_.max_window_s) window_.erase(window_.begin());
  if (window_.back().t - last_attempt_t_ < options_.attempt_every_s) return;
  if (window_.back().t - window_.front().t < options_.init.min_span_s) return;
  last_attempt_t_ = window_.back().t;
  ++attempts_;
  last_ = inertial::initialize_visual_inertial(window_, imu_, options_.init);
  history_.push_back({window_.back().t, last_->span_s, last_->solved ? last_->gravity_sigma_deg : -1});
  if (last_->accepted) {
    accepted_ = last_;
    accepted_at_ = window_.back().t;
    seconds_ = window_.back().t - window_.front().t;
  }
}

namespace {

nlohmann::json vec(const Eigen::Vector3d& v) { return {v.x(), v.y(), v.z()}; }

}  // namespace

nlohmann::json ImuInitMonitor::report() const {
  nlohmann::json j = {{"samples", imu_.samples.size()}, {"attempts", attempts_}, {"initialised", initialised()}};
  const auto& r = result();
  if (!r) return j;
  nlohmann::json init = {{"accepted", r->accepted},
                         {"reason", r->reason},
                         {"frames", r->keyframes},
                         {"span_s", r->span_s},
                         {"rotation_deg", r->rotation_deg},
                         {"solve_ms", r->solve_ms}};
  if (r->accepted) {
    init["at_time_s"] = accepted_at_;
    init["seconds_of_motion"] = seconds_;
  }
  if (r->solved) {
    init["gravity_direction_world"] = vec(r->gravity_direction);
    init["gravity_sigma_deg"] = r->gravity_sigma_deg;
    init["gyro_bias"] = vec(r->bias.gyro);
    init["gyro_bias_sigma"] = vec(r->gyro_bias_sigma);
    init["acc_bias"] = vec(r->bias.acc);
    init["acc_bias_sigma"] = vec(r->acc_bias_sigma);
    init["rms_whitened_residual"] = r->rms_residual;
    const Eigen::Matrix3d R = r->R_gw();
    init["R_gravity_world"] = {R(0, 0), R(0, 1), R(0, 2), R(1, 0), R(1, 1), R(1, 2), R(2, 0), R(2, 1), R(2, 2)};
  }
  j[r->accepted ? "initialisation" : "last_attempt"] = init;
  // Each attempt: its time, the seconds of motion it used, the gravity direction's sigma (-1: not solved).
  nlohmann::json history = nlohmann::json::array();
  for (const Attempt& a : history_) history.push_back({a.t, a.span_s, a.gravity_sigma_deg});
  j["attempts_t_span_sigma_deg"] = history;
  return j;
}

std::string ImuInitMonitor::summary() const {
  const auto& r = result();
  if (!r) return fmt::format("imu: {} samples, no initialisation attempted (too little tracked motion)", imu_.samples.size());
  const std::string biases =
      r->solved ? fmt::format("gyro bias [{:.4f} {:.4f} {:.4f}] rad/s, acc bias [{:.3f} {:.3f} {:.3f}] m/s^2",
                              r->bias.gyro.x(), r->bias.gyro.y(), r->bias.gyro.z(), r->bias.acc.x(), r->bias.acc.y(),
                              r->bias.acc.z())
                : std::string("no estimate");
  if (r->accepted) {
    return fmt::format("imu: initialised at {:.2f} s after {:.2f} s of motion (gravity sigma {:.2f} deg), {}", accepted_at_,
                       seconds_, r->gravity_sigma_deg, biases);
  }
  return fmt::format("imu: not initialised after {} attempts: {}; {}", attempts_, r->reason, biases);
}

}  // namespace plslam::system
