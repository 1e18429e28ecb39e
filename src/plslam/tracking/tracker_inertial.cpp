// The tracker's use of the IMU once the map is gravity-aligned: the IMU chain's start, the IMU's
// prediction of each frame from the last keyframe's estimated state, the pose optimisation with
// the IMU's residual, the frames the IMU carries alone, and the state each new keyframe starts with.
#include <algorithm>
#include <chrono>
#include <cmath>
#include <stdexcept>

#include <spdlog/spdlog.h>

#include "plslam/core/stopwatch.h"
#include "plslam/geometry/stereo_camera.h"
#include "plslam/tracking/projection_search.h"
#include "plslam/tracking/tracker.h"

namespace plslam::tracking {
namespace {

// The IMU's motion from t_i to t_j at `bias`; null when the samples do not cover it.
std::shared_ptr<const inertial::Preintegration> preintegrate(const ImuData& imu, double t_i, double t_j,
                                                             const inertial::ImuBias& bias) {
  try {
    return std::make_shared<const inertial::Preintegration>(imu.samples, t_i, t_j, bias, imu.calibration.noise);
  } catch (const std::invalid_argument& e) {
    spdlog::debug("no IMU motion from {:.3f} to {:.3f} s: {}", t_i, t_j, e.what());
    return nullptr;
  }
}

}  // namespace

void Tracker::use_imu(const ImuData& imu, const inertial::ImuBias& bias) {
  imu_ = &imu;
  T_imu_cam_ = geometry::SE3(imu.T_imu_cam);
  last_bias_ = bias;
  if (!last_keyframe_ || last_keyframe_->is_bad()) return;
  // The chain starts with the last keyframes of the current segment, in time order.
  std::vector<map::KeyFrame*> chain;
  for (map::KeyFrame* kf : map_.keyframes()) {
    if (kf->segment() == last_keyframe_->segment() && kf->id() >= own_keyframes_from_ && kf->id() <= last_keyframe_->id()) {
      chain.push_back(kf);
    }
  }
  const auto n = static_cast<std::size_t>(std::max(0, options_.imu.seed_keyframes));
  if (n > 0 && chain.size() > n) chain.erase(chain.begin(), chain.end() - static_cast<std::ptrdiff_t>(n));
  const geometry::SE3 T_cam_imu = T_imu_cam_.inverse();
  std::vector<geometry::SE3> T_wb;
  std::vector<map::KeyFrameImu> states(chain.size());
  std::vector<const inertial::Preintegration*> intervals(chain.size(), nullptr);
  for (std::size_t k = 0; k < chain.size(); ++k) {
    T_wb.push_back(chain[k]->pose_inverse() * T_cam_imu);
    states[k].bias = bias;
    if (k > 0) {
      states[k].from_previous = preintegrate(imu, chain[k - 1]->timestamp(), chain[k]->timestamp(), bias);
      if (states[k].from_previous) states[k].previous = chain[k - 1];
      intervals[k] = states[k].from_previous.get();
    }
  }
  // Velocity seeds that local BA replaces, from the poses and the IMU between them. Differences of
  // positions left the chain's last keyframe (one neighbour) off by its acceleration times the
  // interval: on a handheld render the first local BA with the IMU then moved it by 5.6 cm, and a
  // frame tracked meanwhile against the moved points was reported 6.9 cm off.
  const auto v = inertial::seed_velocities(T_wb, intervals, bias);
  for (std::size_t k = 0; k < chain.size(); ++k) {
    states[k].v = v[k];
    // No IMU samples on either side: the difference of its neighbours' positions, as before.
    const std::size_t a = k == 0 ? 0 : k - 1, b = std::min(k + 1, chain.size() - 1);
    if (!intervals[k] && (k + 1 == chain.size() || !intervals[k + 1]) && b > a) {
      states[k].v = (T_wb[b].translation() - T_wb[a].translation()) / (chain[b]->timestamp() - chain[a]->timestamp());
    }
    chain[k]->set_imu(states[k]);
  }
  imu_chain_live_ = state_ == TrackingState::kOk;
  spdlog::info("imu: tracking with the IMU from here on; its chain starts with {} keyframes", chain.size());
}

std::optional<Tracker::ImuPrior> Tracker::imu_prior(double t) const {
  if (!imu_ || !imu_chain_live_ || recovery_ || !last_keyframe_ || last_keyframe_->is_bad()) return std::nullopt;
  // The newest keyframe of the chain that a local BA estimated.
  const map::KeyFrame* kf = last_keyframe_;
  std::optional<map::KeyFrameImu> state = kf->imu();
  while (state && !state->estimated && state->previous) {
    kf = state->previous;
    state = kf->imu();
  }
  if (!state || !state->estimated || kf->id() < own_keyframes_from_ || t - kf->timestamp() > options_.imu.max_prediction_s) {
    return std::nullopt;
  }
  const double t_kf = kf->timestamp();
  if (!(t > t_kf)) return std::nullopt;
  ImuPrior prior;
  prior.keyframe = kf;
  prior.pim = preintegrate(*imu_, t_kf, t, state->bias);
  if (!prior.pim) return std::nullopt;
  prior.from = {kf->pose_inverse() * T_imu_cam_.inverse(), state->v, state->bias};
  prior.predicted = inertial::predict(prior.from, *prior.pim);
  prior.T_cw = (prior.predicted.T_wb * T_imu_cam_).inverse().normalized();
  return prior;
}

map::KeyFrameImu Tracker::keyframe_imu(const Frame& f, bool chained) const {
  map::KeyFrameImu s;
  if (f.imu) {
    s.v = f.imu->v;
    s.bias = f.imu->bias;
  } else {
    // Tracked without the IMU (the chain's last state not estimated yet): a seed from the last
    // frame's motion, for local BA to estimate.
    s.bias = last_bias_;
    if (last_ && f.data->timestamp > last_->data->timestamp) {
      const geometry::SE3 T_cam_imu = T_imu_cam_.inverse();
      s.v = ((f.T_cw.inverse() * T_cam_imu).translation() - (last_->T_cw.inverse() * T_cam_imu).translation()) /
            (f.data->timestamp - last_->data->timestamp);
    }
  }
  map::KeyFrame* previous = last_keyframe_;
  if (chained && previous && !previous->is_bad() && previous->id() >= own_keyframes_from_) {
    if (const auto before = previous->imu()) {
      s.from_previous = preintegrate(*imu_, previous->timestamp(), f.data->timestamp, before->bias);
      if (s.from_previous) s.previous = previous;
    }
  }
  return s;
}

optim::PoseOnlyResult Tracker::optimize_pose_inertial(Frame& f, const std::vector<optim::PosePointTerm>& points,
                                                      const std::vector<optim::PoseLineTerm>& lines,
                                                      const optim::PoseOnlyOptions& options) {
  const inertial::InertialTerms terms(*prior_->pim, prior_->from, T_imu_cam_);
  const Eigen::Vector3d v0 = f.imu ? f.imu->v : prior_->predicted.v;
  const inertial::ImuBias b0 = f.imu ? f.imu->bias : prior_->from.bias;
  auto r = inertial::optimize_pose_inertial(geometry::StereoCamera(f.data->calib), terms, f.T_cw, v0, b0, points, lines,
                                            options);
  f.imu = Frame::Imu{r.state.v, r.state.bias};
  return std::move(r.visual);
}

Tracker::NearPrediction Tracker::landmarks_near_imu_prediction(const Frame& f) const {
  // Keyframes near the predicted camera, looking within 45 deg of its direction, nearest first.
  const Eigen::Vector3d centre = f.camera_center();
  const Eigen::Vector3d axis = f.T_cw.rotation().row(2).transpose();
  std::vector<std::pair<double, map::KeyFrame*>> near;
  for (map::KeyFrame* kf : map_.keyframes()) {
    if (kf->is_bad() || !map_.anchored(kf->segment())) continue;
    const Eigen::Vector3d kf_axis = kf->pose().rotation().row(2).transpose();
    if (axis.dot(kf_axis) < std::cos(M_PI / 4)) continue;
    near.emplace_back((kf->camera_center() - centre).norm(), kf);
  }
  const std::size_t n = std::min(near.size(), static_cast<std::size_t>(options_.local_map_covisibles));
  std::partial_sort(near.begin(), near.begin() + static_cast<std::ptrdiff_t>(n), near.end(),
                    [](const auto& a, const auto& b) { return a.first < b.first || (a.first == b.first && a.second->id() < b.second->id()); });
  NearPrediction near_map;
  auto& points = near_map.points;
  auto& lines = near_map.lines;
  core::PointerSet seen_p, seen_l;
  seen_p.assign(f.points, 0);
  seen_l.assign(f.lines, 0);
  for (std::size_t k = 0; k < n; ++k) {
    for (auto* mp : near[k].second->map_points()) {
      if (mp && !mp->is_bad() && seen_p.insert(mp)) points.push_back(mp);
    }
    if (!options_.lines) continue;
    for (auto* ml : near[k].second->map_lines()) {
      if (ml && !ml->is_bad() && seen_l.insert(ml)) lines.push_back(ml);
    }
  }
  near_map.keyframes = n;
  return near_map;
}

bool Tracker::track_from_imu_prediction(Frame& f, TrackStageTimes& t) {
  if (!prior_) return false;
  const auto t0 = std::chrono::steady_clock::now();
  f.T_cw = prior_->T_cw;
  f.clear_matches();
  const auto [points, lines, n] = landmarks_near_imu_prediction(f);
  int found = search_points_in_local_map(f, points, options_.motion_retry_scale * options_.local_map_radius, options_.search);
  if (options_.lines) found += search_lines(f, lines, options_.motion_retry_scale * options_.line_radius, options_.search);
  int inliers = 0;
  if (found >= options_.min_motion_matches) inliers = optimize_pose(f, t);
  f.discard_outliers();
  t.track_motion_ms += ms_since(t0);
  spdlog::debug("frame {}: {} matches in {} keyframes near the IMU's prediction, {} inliers", f.id(), found, n, inliers);
  return inliers >= options_.min_pose_inliers;
}

bool Tracker::map_new_view_from_imu(Frame& f, TrackResult& result) {
  const auto& o = options_.imu;
  if (!prior_ || !o.map_new_views || options_.localization_only) return false;
  if (!within_inertial_window(f.data->timestamp) || !can_start_map(f)) return false;
  f.clear_matches();
  f.T_cw = prior_->T_cw;
  const auto near_map = landmarks_near_imu_prediction(f);
  const int visible = count_visible_points(f, near_map.points);
  const double since_s = f.data->timestamp - *last_visual_t_;
  if (visible >= o.new_view_max_visible_points) {
    spdlog::debug("frame {}: {} map points visible from the IMU's pose, none placed it: not a new view", f.id(), visible);
    return false;
  }
  f.imu = Frame::Imu{prior_->predicted.v, prior_->predicted.bias};
  f.pose_covariance.setZero();
  f.reference = reference_;
  map::KeyFrame* kf = create_keyframe(f);
  // Every stereo point and line, as a map's first keyframe has: the next frames track from them.
  const auto& d = *f.data;
  for (std::size_t i = 0; i < d.keypoints.size(); ++i) {
    if (d.depth[i] > 0 && !f.points[i]) create_stereo_point(f, kf, i);
  }
  if (options_.lines) {
    for (std::size_t j = 0; j < d.lines.size(); ++j) {
      if (d.lines[j].stereo && !f.lines[j]) create_stereo_line(f, kf, j);
    }
  }
  local_keyframes_ = {kf};
  KeyframeInputs in;
  in.frame_id = f.id();
  in.timestamp = d.timestamp;
  in.position = f.camera_center();
  policy_.keyframe_inserted(in);
  result.keyframe = true;
  result.decision.insert = true;
  result.decision.reason = KeyframeReason::kNewView;
  ++inertial_frames_;
  ++new_views_from_imu_;
  spdlog::info("frame {}: a view the map lacks ({} map points visible from the IMU's pose), {:.2f} s after the last "
               "frame vision tracked: mapped from the IMU's pose", f.id(), visible, since_s);
  return true;
}

void Tracker::smooth_inertial_stretches() {
  for (const StretchEnd& end : stretch_ends_) {
    std::size_t first = end.record;
    while (first > 0 && records_[first - 1].state == FrameState::kInertial) --first;
    if (first == 0 || first == end.record || !records_[first - 1].trusted()) continue;
    const double t0 = records_[first - 1].timestamp, t1 = records_[end.record].timestamp;
    const geometry::SE3 T_wc_end = pose_of(records_[end.record]).inverse();
    const geometry::SE3 T_wc_predicted = pose_of(end.predicted).inverse();
    const Eigen::Vector3d dc = T_wc_end.translation() - T_wc_predicted.translation();
    const Eigen::Vector3d dphi = geometry::so3_log(T_wc_end.rotation() * T_wc_predicted.rotation().transpose());
    for (std::size_t k = first; k < end.record; ++k) {
      FrameRecord& rec = records_[k];
      const double w = (rec.timestamp - t0) / (t1 - t0);
      const geometry::SE3 T_wc = pose_of(rec).inverse();
      const geometry::SE3 smoothed(geometry::so3_exp(w * dphi) * T_wc.rotation(), T_wc.translation() + w * dc);
      rec.T_cr = smoothed.inverse() * T_wc * rec.T_cr;
    }
  }
  stretch_ends_.clear();
}

bool Tracker::within_inertial_window(double t) const {
  return last_visual_t_ && t - *last_visual_t_ <= options_.imu.max_inertial_s;
}

bool Tracker::can_carry_by_imu(double t) const {
  return state_ == TrackingState::kOk && within_inertial_window(t) && imu_prior(t).has_value();
}

bool Tracker::carry_by_imu(Frame& f) {
  if (!prior_) return false;
  const Eigen::Vector3d c = prior_->T_cw.inverse().translation();
  spdlog::debug("frame {}: vision failed; the IMU predicts it from keyframe {}, {:.2f} s earlier, at ({:.3f} {:.3f} {:.3f})",
                f.id(), prior_->keyframe->id(), prior_->pim->dt(), c.x(), c.y(), c.z());
  if (!within_inertial_window(f.data->timestamp)) return false;
  if (f.num_stereo_points() >= options_.imu.max_texture_points) return false;
  f.clear_matches();
  f.T_cw = prior_->T_cw;
  f.imu = Frame::Imu{prior_->predicted.v, prior_->predicted.bias};
  f.pose_covariance.setZero();
  f.reference = reference_;
  ++inertial_frames_;
  return true;
}

}  // namespace plslam::tracking
