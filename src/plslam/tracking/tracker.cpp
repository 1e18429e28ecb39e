#include "plslam/tracking/tracker.h"

#include "plslam/core/stopwatch.h"

#include <stdexcept>
#include <algorithm>
#include <chrono>
#include <map>
#include <numbers>
#include <numeric>
#include <unordered_set>

#include <spdlog/spdlog.h>

#include "plslam/geometry/pnp.h"
#include "plslam/geometry/stereo_camera.h"
#include "plslam/tracking/motion_model.h"

namespace plslam::tracking {
namespace {

using Clock = std::chrono::steady_clock;

// How far apart two camera poses are: camera centres in metres, rotation in degrees.
struct PoseGap {
  double m = 0;
  double deg = 0;
};
PoseGap pose_gap(const geometry::SE3& T_aw, const geometry::SE3& T_bw) {
  return {(T_aw.inverse().translation() - T_bw.inverse().translation()).norm(),
          geometry::so3_log(T_aw.rotation() * T_bw.rotation().transpose()).norm() * 180.0 / std::numbers::pi};
}
}  // namespace

const char* to_string(TrackingState s) {
  switch (s) {
    case TrackingState::kNotInitialized: return "INIT";
    case TrackingState::kOk: return "OK";
    case TrackingState::kLost: return "LOST";
  }
  return "?";
}

const char* to_string(FrameState s) {
  switch (s) {
    case FrameState::kLost: return "lost";
    case FrameState::kRecovering: return "recovering";
    case FrameState::kRelocalized: return "relocalized";
    case FrameState::kTracked: return "tracked";
    case FrameState::kLocalized: return "localized";
    case FrameState::kUnanchored: return "unanchored";
    case FrameState::kInertial: return "inertial";
  }
  return "?";
}

Tracker::Tracker(map::Map& map, TrackerOptions options, std::function<void(map::KeyFrame*)> insert_keyframe,
                 std::function<bool()> mapping_idle)
    : map_(map),
      options_(std::move(options)),
      insert_keyframe_(std::move(insert_keyframe)),
      mapping_idle_(std::move(mapping_idle)),
      policy_(options_.keyframe) {}

void Tracker::start_in_loaded_map() {
  if (!records_.empty()) throw std::logic_error("Tracker::start_in_loaded_map after the first frame");
  state_ = TrackingState::kLost;
  own_keyframes_from_ = map_.next_ids().keyframe;
}

double Tracker::close_depth(const Frame& f) const {
  return options_.close_depth_baselines * f.data->calib.baseline;
}

geometry::SE3 Tracker::predicted_pose(const Frame& f) const {
  if (prior_) return prior_->T_cw;
  if (!last_) return f.T_cw;
  if (!velocity_) return last_->T_cw;
  return predict_pose(*velocity_, velocity_dt_, f.data->timestamp - last_->data->timestamp, last_->T_cw);
}

std::vector<long> Tracker::local_keyframe_ids() const {
  std::vector<long> ids;
  ids.reserve(local_keyframes_.size());
  for (const auto* kf : local_keyframes_) ids.push_back(kf->id());
  return ids;
}

std::vector<long> Tracker::local_point_ids() const {
  std::vector<long> ids;
  ids.reserve(local_points_.size());
  for (const auto* p : local_points_) ids.push_back(p->id());
  return ids;
}

Tracker::TrackedFeatures Tracker::last_tracked_features() const {
  TrackedFeatures out;
  if (!last_) return out;
  const auto& f = *last_;
  for (std::size_t i = 0; i < f.points.size(); ++i) {
    if (f.points[i] && !f.point_outlier[i]) out.points.push_back(f.data->keypoints[i].pt);
  }
  for (std::size_t i = 0; i < f.lines.size(); ++i) {
    if (f.lines[i] && !f.line_outlier[i]) {
      const auto& s = f.data->lines[i].segment;
      out.lines.emplace_back(s.start, s.end);
    }
  }
  return out;
}

Tracker::Anchor Tracker::anchor_of(const FrameRecord& r) {
  geometry::SE3 T_cr = r.T_cr;
  map::KeyFrame* ref = r.reference;
  // Culled keyframes hand their frames over to their parents.
  while (ref && ref->is_bad()) {
    T_cr = T_cr * ref->pose_relative_to_parent();
    ref = ref->parent();
  }
  return {ref, T_cr};
}

geometry::SE3 Tracker::Anchor::T_cw() const { return keyframe ? T_ck * keyframe->pose() : T_ck; }

geometry::SE3 Tracker::pose_of(const FrameRecord& r) { return anchor_of(r).T_cw(); }

void Tracker::transform_world(const geometry::SE3& T_new_old) {
  const geometry::SE3 T_old_new = T_new_old.inverse();
  if (last_) last_->T_cw = last_->T_cw * T_old_new;
  if (recovery_) recovery_->T_cw = recovery_->T_cw * T_old_new;
  for (FrameRecord& r : records_) {
    if (!r.reference) r.T_cr = r.T_cr * T_old_new;
  }
  policy_.transform_world(T_new_old);
}

bool Tracker::check_motion(const Frame& f) {
  const auto [m, deg] = pose_gap(f.T_cw, predicted_pose(f));
  motion_deviation_m_.push_back(m);
  motion_deviation_deg_.push_back(deg);
  const bool far = options_.jump_deviation_m > 0 && m > options_.jump_deviation_m;
  const bool turned = options_.jump_deviation_deg > 0 && deg > options_.jump_deviation_deg;
  if (!far && !turned) return false;
  suspect_jumps_.push_back({f.id(), m, deg});
  spdlog::warn("frame {}: suspect jump: the tracked pose is {:.2f} m and {:.1f} deg from the motion model's "
               "prediction (limits {} m, {} deg)",
               f.id(), m, deg, options_.jump_deviation_m, options_.jump_deviation_deg);
  return true;
}

bool Tracker::beyond_reach(const Frame& f) {
  const auto& o = options_.relocalization;
  if (velocity_ || o.max_speed <= 0 || !last_ || records_.empty() || !records_.back().tracked) return false;
  const double dt = std::max(0.0, f.data->timestamp - last_->data->timestamp);
  const double moved = (f.camera_center() - last_->camera_center()).norm();
  const double reach = o.max_speed * dt + options_.jump_deviation_m;
  if (moved <= reach) return false;
  suspect_jumps_.push_back({f.id(), moved, 0.0});
  spdlog::warn("frame {}: the tracked pose is {:.2f} m from the last one, {:.2f} s earlier: further than a camera "
               "moves (relocalization.max_speed {} m/s)",
               f.id(), moved, dt, o.max_speed);
  return true;
}

Tracker::RecoveryCheck Tracker::check_recovery(const Frame& f, bool jumped) const {
  if (jumped) return RecoveryCheck::kRefuted;
  const auto& o = options_.relocalization;
  const auto e = explained(f, local_points_);
  const auto coverage = o.min_cell_coverage > 0 ? cell_coverage(f, local_points_) : CellCoverage{};
  spdlog::debug("frame {}: recovering ({} of {} frames): {} of {} visible local map points matched, inliers in {} "
                "of {} cells",
                f.id(), recovery_->frames + 1, o.confirm_frames + recovery_->cell_misses, e.matched, e.visible,
                coverage.covered, coverage.predicted);
  if (!e.enough) return RecoveryCheck::kRefuted;
  if (o.min_cell_coverage <= 0 || coverage.share() >= o.min_cell_coverage) return RecoveryCheck::kHolds;
  // A look-alike fails most of its frames; a true place may dip once after holding twice.
  const bool forgiven = recovery_->cell_misses < o.max_cell_misses && recovery_->held() >= 2;
  return forgiven ? RecoveryCheck::kCellMiss : RecoveryCheck::kRefuted;
}

Tracker::Explained Tracker::explained(const Frame& f, const std::vector<map::MapPoint*>& points) const {
  Explained e;
  e.matched = f.num_matched_points();
  e.visible = count_visible_points(f, points);
  e.enough = e.matched >= options_.relocalization.min_found_ratio * e.visible;
  return e;
}

TrackResult Tracker::track(std::shared_ptr<const map::FrameData> data) {
  Frame f(std::move(data));
  TrackResult result;
  // Tracking reads poses and structure that local BA writes: hold the map-update lock for the
  // whole step so it never sees half an update.
  std::unique_lock map_lock(map_.update_mutex());
  // A loop correction moved the keyframes: the last frame keeps its pose relative to its reference.
  if (const long changes = map_.big_changes(); changes != seen_big_changes_) {
    seen_big_changes_ = changes;
    if (last_ && !records_.empty() && records_.back().reference) last_->T_cw = pose_of(records_.back());
  }
  prior_.reset();
  if (state_ == TrackingState::kOk) prior_ = imu_prior(f.data->timestamp);
  std::optional<FrameRecord> stretch_end_predicted;
  if (prior_ && last_carried_) {
    stretch_end_predicted = records_.back();
    stretch_end_predicted->T_cr = prior_->T_cw * pose_of(records_.back()).inverse() * records_.back().T_cr;
  }
  bool inertial = false;
  bool new_view = false;  // inertial, and a keyframe whose new points the next frame searches

  bool ok = false;
  if (state_ == TrackingState::kNotInitialized) {
    ok = initialize(f);
    if (ok) {
      result.keyframe = true;
      state_ = TrackingState::kOk;
    }
  } else if (state_ == TrackingState::kLost) {
    ok = relocalize_and_track(f, result);
    if (!ok) {
      f.clear_matches();
      // A new map segment starts where the motion model puts the camera, so the trajectory stays
      // continuous across the loss.
      f.T_cw = predicted_pose(f);
      if (should_start_new_segment(f) && initialize(f)) {
        ok = true;
        result.keyframe = true;
        result.new_map_segment = true;
        state_ = TrackingState::kOk;
        lost_since_.reset();
        new_segment_frames_.push_back(f.id());
      }
    }
  } else {
    bool tracked = false;
    // While recovering, the frame right after the relocalization has no velocity: its matches are
    // searched around the last pose (the motion model's wide retry covers the motion), which on a
    // reversed path keeps many more than matching the reference keyframe's descriptors.
    if (velocity_ || recovery_) tracked = track_with_motion_model(f, result.times);
    if (!tracked) tracked = track_reference_keyframe(f, result.times);
    if (!tracked) tracked = track_from_imu_prediction(f, result.times);
    if (tracked) {
      tracked = track_local_map(f, result.times, result.point_inliers, result.line_inliers);
    }
    bool jumped = false;
    if (tracked && beyond_reach(f)) {
      // No velocity to predict with (the frame after a relocalization or a new map), and a move no
      // camera makes in the time: a pose on another place, never kept.
      tracked = false;
    } else if (tracked && velocity_ && check_motion(f)) {
      // A pose far from the prediction that explains little of what the map shows there is a
      // look-alike place (after a black-out the motion model is a second or more out of date).
      jumped = true;
      const auto e = explained(f, local_points_);
      spdlog::log(e.enough ? spdlog::level::info : spdlog::level::warn,
                  "frame {}: {} of the {} local map points visible from the jumped pose matched: {}", f.id(), e.matched,
                  e.visible, e.enough ? "kept" : "a look-alike place, relocalizing");
      tracked = e.enough;
    }
    // Tracked across a gap (a black-out, unreadable frames): the motion model is stale, and a
    // look-alike where it points would be tracked as if the camera had not been moved. The pose
    // recovers like a relocalization's, this frame checked too.
    const double gap = f.data->timestamp - last_->data->timestamp;
    // (The IMU carried the pose across the gap: it is no guess.)
    if (tracked && !recovery_ && !prior_ && options_.recover_after_gap_s > 0 && gap > options_.recover_after_gap_s) {
      spdlog::info("frame {}: tracked after a {:.2f} s gap, recovering until confirmed", f.id(), gap);
      recovery_ = Recovery{f.id(), 0, f.T_cw, true, trusted_since_recovery_};
      trusted_since_recovery_ = false;
    }
    const auto check = tracked && recovery_ ? check_recovery(f, jumped) : RecoveryCheck::kHolds;
    if (check == RecoveryCheck::kCellMiss) {
      ++recovery_->cell_misses;
      spdlog::info("frame {}: recovering from frame {} with inliers in too few image cells (miss {} of {} forgiven)",
                   f.id(), recovery_->since_frame, recovery_->cell_misses, options_.relocalization.max_cell_misses);
    }
    if (check == RecoveryCheck::kRefuted) {
      spdlog::warn("frame {}: the {} of frame {} is refuted after {} frames", f.id(),
                   recovery_->after_gap ? "tracking after the gap" : "relocalization", recovery_->since_frame,
                   recovery_->frames);
      if (!recovery_->after_gap) refuted_relocalizations_.push_back(recovery_->since_frame);
      // Refuted on its own first frame, the tracking across the gap put no pose into the motion
      // model: a relocalization of this frame that lands on the prediction from the last trusted
      // frame still continues the trusted trajectory (continuity_s).
      if (recovery_->frames == 0) trusted_since_recovery_ = recovery_->trusted_before;
      tracked = false;
    }
    if (tracked) {
      ok = true;
      velocity_ = (f.T_cw * last_->T_cw.inverse()).normalized();
      velocity_dt_ = f.data->timestamp - last_->data->timestamp;
      if (recovery_ && check == RecoveryCheck::kHolds) {
        ++recovery_->frames;
        if (recovery_confirmed(f)) confirm_relocalization(f, result);
      }
      finish_tracked_frame(f, result);
      last_visual_t_ = f.data->timestamp;
      if (f.imu) {
        last_bias_ = f.imu->bias;
        ++imu_tracked_frames_;
      }
    } else if (!recovery_ && carry_by_imu(f)) {
      ok = true;
      inertial = true;
    } else if (!recovery_ && map_new_view_from_imu(f, result)) {
      ok = true;
      inertial = true;
      new_view = true;
    } else {
      recovery_.reset();
      prior_.reset();
      imu_chain_live_ = false;
      ++lost_events_;
      const bool relocalizing = relocalization_on();
      spdlog::warn("frame {}: tracking lost (event {}), {}", f.id(), lost_events_,
                   relocalizing ? "relocalizing" : "starting a new map segment");
      state_ = TrackingState::kLost;
      lost_since_.reset();
      // The frame that lost track is the first chance to find the camera again.
      ok = relocalizing && relocalize_and_track(f, result);
      if (!ok && can_start_map(f)) lost_since_ = f.data->timestamp;  // the relocalization timeout starts
      if (!ok) {
        // The motion model's prediction: where a new map segment would start. It is not a tracked
        // pose (the record says so), and the trajectory outputs never present it as one.
        f.T_cw = predicted_pose(f);
        f.clear_matches();
      }
    }
  }

  if (!f.reference) f.reference = reference_;
  FrameState fs = FrameState::kLost;
  if (ok) {
    if (recovery_) {
      fs = FrameState::kRecovering;
    } else if (options_.localization_only) {
      fs = FrameState::kLocalized;
    } else if (f.reference && !map_.anchored(f.reference->segment())) {
      fs = FrameState::kUnanchored;
    } else {
      fs = result.relocalized ? FrameState::kRelocalized : FrameState::kTracked;
    }
    if (inertial) fs = FrameState::kInertial;
  }
  FrameRecord rec;
  rec.frame_id = f.id();
  rec.timestamp = f.data->timestamp;
  rec.reference = f.reference;
  rec.T_cr = f.reference ? f.T_cw * f.reference->pose_inverse() : f.T_cw;
  rec.tracked = ok;
  rec.state = fs;
  records_.push_back(rec);
  const bool carried = inertial && !new_view;
  if (rec.trusted()) {
    last_tracked_record_ = records_.size() - 1;
    trusted_since_recovery_ = true;
    if (stretch_end_predicted && !carried) stretch_ends_.push_back({records_.size() - 1, *stretch_end_predicted});
  }
  last_carried_ = carried;
  result.state = state_;
  result.frame_state = fs;
  if (ok) result.pose_covariance = f.pose_covariance;
  result.tracked = rec.trusted();
  // An inertial frame matched nothing: the next frame searches the last one vision tracked.
  if (!inertial || new_view) last_ = std::move(f);
  return result;
}

void Tracker::settle_states() {
  for (auto& rec : records_) {
    if (rec.state == FrameState::kUnanchored && rec.reference && map_.anchored(rec.reference->segment())) {
      rec.state = FrameState::kTracked;
    }
  }
  smooth_inertial_stretches();
}

bool Tracker::relocalize_and_track(Frame& f, TrackResult& result) {
  long against = -1;
  if (!relocalize(f, result.times, against) ||
      !track_local_map(f, result.times, result.point_inliers, result.line_inliers)) {
    return false;
  }
  state_ = TrackingState::kOk;
  result.relocalized_against = against;
  lost_since_.reset();
  const bool continues = continues_trusted_motion(f);
  // The frames since the loss carry predictions, not poses: no velocity across them.
  velocity_.reset();
  spdlog::info("frame {}: relocalized against keyframe {} ({} point and {} line inliers){}", f.id(), against,
               result.point_inliers, result.line_inliers,
               continues ? ", where the motion before the loss puts it"
                         : (options_.relocalization.confirm_frames > 1 ? ", recovering until confirmed" : ""));
  recovery_ = Recovery{f.id(), 1, f.T_cw};
  trusted_since_recovery_ = false;
  if (continues || recovery_confirmed(f)) confirm_relocalization(f, result);
  finish_tracked_frame(f, result);
  return true;
}

bool Tracker::continues_trusted_motion(const Frame& f) const {
  const auto& o = options_.relocalization;
  if (o.continuity_s <= 0 || !velocity_ || !last_ || !last_tracked_record_ || !trusted_since_recovery_) return false;
  if (f.data->timestamp - records_[*last_tracked_record_].timestamp > o.continuity_s) return false;
  // The frames since the trusted one are lost: last_ carries the motion model's chained prediction.
  const auto gap = pose_gap(f.T_cw, predicted_pose(f));
  return gap.m <= options_.jump_deviation_m && gap.deg <= options_.jump_deviation_deg;
}

bool Tracker::recovery_confirmed(const Frame& f) const {
  const auto& o = options_.relocalization;
  // Each forgiven miss asks one more frame that holds.
  if (recovery_->frames < o.confirm_frames + recovery_->cell_misses) return false;
  if (o.confirm_distance_m <= 0 && o.confirm_angle_deg <= 0) return true;
  const auto gap = pose_gap(f.T_cw, recovery_->T_cw);
  return (o.confirm_distance_m > 0 && gap.m >= o.confirm_distance_m) ||
         (o.confirm_angle_deg > 0 && gap.deg >= o.confirm_angle_deg);
}

void Tracker::confirm_relocalization(const Frame& f, TrackResult& result) {
  if (!recovery_->after_gap) {
    result.relocalized = true;
    relocalized_frames_.push_back(recovery_->since_frame);
  }
  if (recovery_->since_frame != f.id()) {
    spdlog::info("frame {}: the {} of frame {} is confirmed", f.id(),
                 recovery_->after_gap ? "tracking after the gap" : "relocalization", recovery_->since_frame);
  }
  recovery_.reset();
}

void Tracker::finish_tracked_frame(Frame& f, TrackResult& result) {
  const auto inputs = keyframe_inputs(f, result.point_inliers, result.line_inliers);
  result.decision = policy_.decide(inputs);
  if (result.decision.queue_full) ++keyframes_refused_queue_full_;
  result.keyframe_inputs = inputs;
  result.local_keyframes = static_cast<int>(local_keyframes_.size());
  result.local_points = static_cast<int>(local_points_.size());
  result.local_lines = static_cast<int>(local_lines_.size());
  // No keyframe from an unconfirmed relocalization: a look-alike place must not grow the map.
  // With the IMU, keyframes stay close in time for preintegration.
  if (imu_ && !result.decision.insert && !result.decision.queue_full && last_keyframe_ &&
      f.data->timestamp - last_keyframe_->timestamp() >= options_.imu.max_keyframe_interval_s) {
    result.decision.insert = true;
    result.decision.reason = KeyframeReason::kImuInterval;
  }
  if (result.decision.insert && !options_.localization_only && !recovery_) {
    create_keyframe(f);
    policy_.keyframe_inserted(inputs);
    result.keyframe = true;
  }
  f.discard_outliers();
}

bool Tracker::can_start_map(const Frame& f) const { return f.num_stereo_points() >= options_.init_min_points; }

bool Tracker::should_start_new_segment(const Frame& f) {
  if (options_.localization_only) return false;
  if (!relocalization_on()) return true;
  if (!can_start_map(f)) return false;  // could not start one anyway
  if (!lost_since_) lost_since_ = f.data->timestamp;
  // (1 us of slack: 10 frames at 10 Hz are 0.99999... s apart in floating point)
  return f.data->timestamp - *lost_since_ >= options_.relocalization.new_segment_after_s - 1e-6;
}

bool Tracker::initialize(Frame& f) {
  const auto& d = *f.data;
  if (!can_start_map(f)) return false;
  // The first map is segment 0, anchored; a later one starts where the motion model guesses.
  const int segment = map_.first_keyframe() ? map_.start_segment() : 0;
  map::KeyFrame* kf = map_.create_keyframe(f.data, f.T_cw, segment);
  for (std::size_t i = 0; i < d.keypoints.size(); ++i) {
    if (d.depth[i] > 0) create_stereo_point(f, kf, i);
  }
  if (options_.lines) {
    for (std::size_t j = 0; j < d.lines.size(); ++j) {
      if (d.lines[j].stereo) create_stereo_line(f, kf, j);
    }
  }
  if (imu_) {
    kf->set_imu(keyframe_imu(f, /*chained=*/false));  // a new segment: a new chain
    imu_chain_live_ = true;
  }
  f.reference = kf;
  reference_ = kf;
  last_keyframe_ = kf;
  local_keyframes_ = {kf};
  velocity_.reset();
  insert_keyframe_(kf);
  KeyframeInputs in;
  in.frame_id = f.id();
  in.timestamp = d.timestamp;
  in.position = f.camera_center();
  policy_.keyframe_inserted(in);
  spdlog::info("frame {}: new map segment with {} points and {} lines", f.id(), map_.num_points(),
               map_.num_lines());
  return true;
}

int Tracker::optimize_pose(Frame& f, TrackStageTimes& t, bool covariance) {
  const auto t0 = Clock::now();
  const auto& d = *f.data;
  std::vector<optim::PosePointTerm> pts;
  std::vector<std::size_t> pidx;
  for (std::size_t i = 0; i < f.points.size(); ++i) {
    map::MapPoint* mp = f.points[i];
    if (!mp) continue;
    pts.push_back({mp->position(), d.point_observation(i, options_.far_stereo_baselines)});
    pidx.push_back(i);
  }
  std::vector<optim::PoseLineTerm> lns;
  std::vector<std::size_t> lidx;
  for (std::size_t j = 0; j < f.lines.size(); ++j) {
    map::MapLine* ml = f.lines[j];
    if (!ml) continue;
    optim::PoseLineTerm term;
    term.start = ml->start();
    term.end = ml->end();
    term.obs.left_line = d.lines[j].left_line;
    term.obs.right_line = d.lines[j].right_line;
    term.obs.information = options_.line_information;
    lns.push_back(term);
    lidx.push_back(j);
  }
  const geometry::StereoCamera cam(d.calib);
  auto popts = options_.pose;
  popts.scale_factor = d.scale_factor;
  popts.covariance = covariance;
  const auto r = prior_ ? optimize_pose_inertial(f, pts, lns, popts) : optim::optimize_pose(cam, f.T_cw, pts, lns, popts);
  f.T_cw = r.T_cw.normalized();
  f.pose_covariance = r.covariance;
  for (std::size_t k = 0; k < pidx.size(); ++k) f.point_outlier[pidx[k]] = r.point_outlier[k];
  for (std::size_t k = 0; k < lidx.size(); ++k) f.line_outlier[lidx[k]] = r.line_outlier[k];
  t.pose_optimization_ms += ms_since(t0);
  return r.num_point_inliers + r.num_line_inliers;
}

bool Tracker::track_with_motion_model(Frame& f, TrackStageTimes& t) {
  const auto t0 = Clock::now();
  const geometry::SE3 predicted = predicted_pose(f);
  std::vector<map::MapLine*> last_lines;
  if (options_.lines) {
    for (std::size_t j = 0; j < last_->lines.size(); ++j) {
      if (last_->lines[j] && !last_->line_outlier[j]) last_lines.push_back(last_->lines[j]);
    }
  }
  // One attempt: search the last frame's matches around the prediction within `scale` times
  // the normal windows, then optimise. Returns the matches found; `inliers` is 0 when too few.
  auto attempt = [&](double scale, int& inliers) {
    f.T_cw = predicted;
    f.clear_matches();
    int n = search_points_from_frame(f, *last_, scale * options_.motion_radius, options_.search);
    if (options_.lines) n += search_lines(f, last_lines, scale * options_.line_radius, options_.search);
    inliers = n >= options_.min_motion_matches ? optimize_pose(f, t) : 0;
    return n;
  };
  int inliers = 0;
  int n = attempt(1.0, inliers);
  if (n < options_.min_motion_matches) n = attempt(2.0, inliers);  // ORB-SLAM2's second window
  // A sudden change of motion (a car entering a turn: 1 degree of unexpected yaw is 12 px on
  // KITTI) moves most true matches out of the window. The matches found are then mostly wrong,
  // and the optimisation, pulled between them, keeps few as inliers and settles on a wrong pose
  // that local map tracking would confirm. So a low inlier share, or few matches for the points
  // the last frame tracked, means: search again in a window wide enough for the change and keep
  // whichever attempt explains more matches.
  const bool few_matches = n < options_.motion_min_match_share * last_->num_matched_points();
  if (n >= options_.min_motion_matches && (inliers < options_.motion_min_inlier_share * n || few_matches)) {
    const Frame narrow = f;
    const int narrow_inliers = inliers;
    ++motion_wide_retries_;
    attempt(options_.motion_retry_scale, inliers);
    if (inliers <= narrow_inliers) {
      f = narrow;
      inliers = narrow_inliers;
    }
  }
  f.discard_outliers();
  const bool ok = inliers >= options_.min_pose_inliers;
  if (!ok) f.clear_matches();
  t.track_motion_ms += ms_since(t0);
  return ok;
}

std::optional<geometry::SE3> Tracker::pnp_from_matches(const Frame& f) const {
  std::vector<Eigen::Vector3d> world;
  std::vector<Eigen::Vector2d> pixels;
  for (std::size_t i = 0; i < f.points.size(); ++i) {
    const map::MapPoint* mp = f.points[i];
    if (!mp || mp->is_bad()) continue;
    world.push_back(mp->position());
    const auto& pt = f.data->keypoints[i].pt;
    pixels.emplace_back(pt.x, pt.y);
  }
  if (world.size() < static_cast<std::size_t>(options_.min_pnp_matches)) return std::nullopt;
  const auto r = geometry::solve_pnp_ransac(geometry::StereoCamera(f.data->calib), world, pixels);
  if (!r.success) return std::nullopt;
  return r.T_cw;
}

bool Tracker::track_reference_keyframe(Frame& f, TrackStageTimes& t) {
  const auto t0 = Clock::now();
  bool ok = false;
  if (reference_) {
    const int n = match_to_keyframe(f, *reference_, options_.reference_match_ratio, options_.search);
    if (n >= options_.min_reference_matches) {
      // Without a velocity (the first frame of a map, or after the motion model failed) the
      // optimisation starts from the last pose. A car moves 1-3 m per frame: far enough for it to
      // settle on a wrong pose that still keeps many matches (KITTI 01 started one frame later
      // was tracked at 0.5 m/s instead of 10, ATE 7.3 m, every frame "OK"). PnP RANSAC on the
      // same matches gives a second start; the optimisation that keeps more inliers wins.
      const Frame matched = f;
      f.T_cw = prior_ ? prior_->T_cw : last_->T_cw;
      int inliers = optimize_pose(f, t);
      if (const auto pnp = pnp_from_matches(matched); pnp) {
        Frame from_pnp = matched;
        from_pnp.T_cw = *pnp;
        const int pnp_inliers = optimize_pose(from_pnp, t);
        if (pnp_inliers > inliers) {
          f = std::move(from_pnp);
          inliers = pnp_inliers;
        }
      }
      f.discard_outliers();
      ok = inliers >= options_.min_pose_inliers;
    }
  }
  t.track_motion_ms += ms_since(t0);
  return ok;
}

void Tracker::update_local_map(Frame& f) {
  // Local keyframes: those observing the frame's matches, their best covisibles, and their
  // spanning-tree neighbours.
  map::IdMap<map::KeyFrame, int> counter;
  for (std::size_t i = 0; i < f.points.size(); ++i) {
    map::MapPoint* mp = f.points[i];
    if (!mp || mp->is_bad()) {
      f.points[i] = nullptr;
      continue;
    }
    mp->for_each_observation([&](map::KeyFrame* kf, int) { ++counter[kf]; });
  }
  for (std::size_t j = 0; j < f.lines.size(); ++j) {
    map::MapLine* ml = f.lines[j];
    if (!ml || ml->is_bad()) {
      f.lines[j] = nullptr;
      continue;
    }
    ml->for_each_observation([&](map::KeyFrame* kf, int) { ++counter[kf]; });
  }
  local_keyframes_.clear();
  std::unordered_set<map::KeyFrame*> in_set;
  map::KeyFrame* best = nullptr;
  int best_count = 0;
  for (const auto& [kf, c] : counter) {
    if (kf->is_bad()) continue;
    if (c > best_count) {
      best_count = c;
      best = kf;
    }
    if (in_set.insert(kf).second) local_keyframes_.push_back(kf);
  }
  const std::size_t direct = local_keyframes_.size();
  for (std::size_t k = 0; k < direct && local_keyframes_.size() < static_cast<std::size_t>(options_.local_keyframes_max); ++k) {
    map::KeyFrame* kf = local_keyframes_[k];
    for (auto* n : kf->best_covisibles(static_cast<std::size_t>(options_.local_map_covisibles))) {
      if (!n->is_bad() && in_set.insert(n).second) local_keyframes_.push_back(n);
    }
    for (auto* c : kf->children()) {
      if (!c->is_bad() && in_set.insert(c).second) local_keyframes_.push_back(c);
    }
    if (auto* p = kf->parent(); p && !p->is_bad() && in_set.insert(p).second) local_keyframes_.push_back(p);
  }
  if (best) {
    reference_ = best;
    f.reference = best;
  }
  local_points_.clear();
  local_lines_.clear();
  // Members, not locals: their arrays are kept from frame to frame.
  seen_points_.assign(f.points, local_points_.capacity());
  seen_lines_.assign(f.lines, local_lines_.capacity());
  for (auto* kf : local_keyframes_) {
    for (auto* mp : kf->map_points()) {
      if (mp && !mp->is_bad() && seen_points_.insert(mp)) local_points_.push_back(mp);
    }
    if (options_.lines) {
      for (auto* ml : kf->map_lines()) {
        if (ml && !ml->is_bad() && seen_lines_.insert(ml)) local_lines_.push_back(ml);
      }
    }
  }
}

bool Tracker::track_local_map(Frame& f, TrackStageTimes& t, int& point_inliers, int& line_inliers) {
  const auto t0 = Clock::now();
  update_local_map(f);
  search_points_in_local_map(f, local_points_, options_.local_map_radius, options_.search);
  if (options_.lines) search_lines(f, local_lines_, options_.line_radius, options_.search);
  optimize_pose(f, t, /*covariance=*/true);
  point_inliers = 0;
  line_inliers = 0;
  for (std::size_t i = 0; i < f.points.size(); ++i) {
    map::MapPoint* mp = f.points[i];
    if (!mp) continue;
    if (f.point_outlier[i]) continue;
    mp->increase_found();
    if (mp->num_observations() > 0) ++point_inliers;
  }
  for (std::size_t j = 0; j < f.lines.size(); ++j) {
    map::MapLine* ml = f.lines[j];
    if (!ml || f.line_outlier[j]) continue;
    ml->increase_found();
    if (ml->num_observations() > 0) ++line_inliers;
  }
  t.track_local_map_ms += ms_since(t0);
  return point_inliers + line_inliers >= options_.min_local_inliers;
}

KeyframeInputs Tracker::keyframe_inputs(const Frame& f, int point_inliers, int line_inliers) const {
  KeyframeInputs in;
  in.frame_id = f.id();
  in.timestamp = f.data->timestamp;
  in.position = f.T_cw.inverse().translation();
  in.tracked_inliers = point_inliers + line_inliers;
  const int nkf = static_cast<int>(map_.num_keyframes());
  const int min_obs = nkf <= 2 ? 2 : 3;
  in.reference_tracked = reference_ ? reference_->tracked_map_points(min_obs) + reference_->tracked_map_lines(min_obs) : 0;
  in.keyframes_in_map = nkf;
  in.local_mapping_idle = mapping_idle_();
  in.keyframes_queued = mapping_queue_ ? static_cast<int>(mapping_queue_()) : 0;
  const double th = close_depth(f);
  for (std::size_t i = 0; i < f.points.size(); ++i) {
    const float z = f.data->depth[i];
    if (z <= 0 || z >= th) continue;
    if (f.points[i] && !f.point_outlier[i]) {
      ++in.tracked_close;
    } else {
      ++in.untracked_close;
    }
  }
  return in;
}

void Tracker::drop_bad_landmarks() {
  if (last_) {
    for (auto& p : last_->points) {
      if (p && p->is_bad()) p = nullptr;
    }
    for (auto& l : last_->lines) {
      if (l && l->is_bad()) l = nullptr;
    }
  }
  std::erase_if(local_points_, [](const map::MapPoint* p) { return p->is_bad(); });
  std::erase_if(local_lines_, [](const map::MapLine* l) { return l->is_bad(); });
}

void Tracker::create_stereo_point(Frame& f, map::KeyFrame* kf, std::size_t i) {
  const auto& d = *f.data;
  const geometry::StereoCamera cam(d.calib);
  const Eigen::Vector3d Xc = cam.unproject({d.keypoints[i].pt.x, d.keypoints[i].pt.y}, d.depth[i]);
  map::MapPoint* mp = map_.create_point(f.T_cw.inverse() * Xc, kf, f.id());
  mp->add_observation(kf, static_cast<int>(i));
  kf->add_map_point(mp, static_cast<int>(i));
  mp->update_descriptor();
  mp->update_normal_and_depth();
  f.points[i] = mp;
  f.point_outlier[i] = false;
}

void Tracker::create_stereo_line(Frame& f, map::KeyFrame* kf, std::size_t j) {
  const auto& l = f.data->lines[j];
  const geometry::SE3 T_wc = f.T_cw.inverse();
  map::MapLine* ml = map_.create_line(T_wc * l.start_cam, T_wc * l.end_cam, kf, f.id());
  ml->add_observation(kf, static_cast<int>(j));
  kf->add_map_line(ml, static_cast<int>(j));
  ml->update_descriptor();
  ml->update_normal_and_depth();
  f.lines[j] = ml;
  f.line_outlier[j] = false;
}

map::KeyFrame* Tracker::create_keyframe(Frame& f) {
  const auto& d = *f.data;
  // The frame's pose is in its reference keyframe's segment (a relocalization into the first map
  // leaves a new segment behind).
  map::KeyFrame* kf = map_.create_keyframe(f.data, f.T_cw, reference_ ? reference_->segment() : 0);
  // Tracked map points and lines: associated now, observations added by local mapping.
  for (std::size_t i = 0; i < f.points.size(); ++i) {
    if (f.points[i] && !f.point_outlier[i]) kf->add_map_point(f.points[i], static_cast<int>(i));
  }
  for (std::size_t j = 0; j < f.lines.size(); ++j) {
    if (f.lines[j] && !f.line_outlier[j]) kf->add_map_line(f.lines[j], static_cast<int>(j));
  }
  // New stereo points, closest first: all close ones, and at least new_keyframe_points.
  std::vector<std::size_t> order;
  for (std::size_t i = 0; i < d.depth.size(); ++i) {
    if (d.depth[i] > 0) order.push_back(i);
  }
  std::sort(order.begin(), order.end(), [&](std::size_t a, std::size_t b) { return d.depth[a] < d.depth[b]; });
  const double th = close_depth(f);
  int count = 0;
  for (std::size_t i : order) {
    if (d.depth[i] > th && count >= options_.new_keyframe_points) break;
    ++count;
    if (f.points[i] && !f.point_outlier[i] && f.points[i]->num_observations() > 0) continue;
    create_stereo_point(f, kf, i);
  }
  if (options_.lines) {
    for (std::size_t j = 0; j < d.lines.size(); ++j) {
      const auto& l = d.lines[j];
      if (!l.stereo || (f.lines[j] && !f.line_outlier[j])) continue;
      if (0.5 * (l.start_cam.z() + l.end_cam.z()) > th) continue;
      create_stereo_line(f, kf, j);
    }
  }
  if (imu_) {
    kf->set_imu(keyframe_imu(f, imu_chain_live_));
    imu_chain_live_ = true;
  }
  reference_ = kf;
  f.reference = kf;
  last_keyframe_ = kf;
  insert_keyframe_(kf);
  return kf;
}

}  // namespace plslam::tracking
