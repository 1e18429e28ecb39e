#include "plslam/system/run_report.h"

#include "plslam/core/sample_stats.h"

#include <algorithm>
#include <cmath>
#include <fstream>
#include <numeric>
#include <unordered_map>

#include <fmt/format.h>

#include "plslam/core/error.h"
#include "plslam/eval/evaluate.h"

namespace plslam::system {
namespace {

nlohmann::json loops_json(const System& slam) {
  nlohmann::json out = nlohmann::json::array();
  if (!slam.loop_closer()) return out;
  for (const auto& l : slam.loop_closer()->stats().loops) {
    out.push_back({{"frame", l.frame}, {"keyframe", l.keyframe}, {"matched_keyframe", l.matched_keyframe},
                   {"matched_frame", l.matched_frame}, {"inliers", l.inliers}, {"fused_points", l.fused_points},
                   {"fused_lines", l.fused_lines}, {"correction_ms", l.correction_ms}});
  }
  return out;
}

std::vector<double> loop_correction_ms(const System& slam) {
  std::vector<double> out;
  if (slam.loop_closer()) {
    for (const auto& l : slam.loop_closer()->stats().loops) out.push_back(l.correction_ms);
  }
  return out;
}

nlohmann::json loop_closing_json(const System& slam) {
  if (!slam.loop_closer()) return {{"enabled", false}};
  const auto s = slam.loop_closer()->stats();
  return {{"enabled", true}, {"detections", s.detections}, {"rejected", s.rejected}, {"implausible", s.implausible},
          {"global_ba_after_relocalization", s.global_ba_after_relocalization},
          {"global_ba_inertial_refinements", s.global_ba_inertial_refinements},
          {"loops_across_relocalization", s.loops_across_relocalization}};
}

nlohmann::json global_ba_ms(const System& slam) {
  return slam.loop_closer() ? nlohmann::json(slam.loop_closer()->stats().global_ba_ms) : nlohmann::json::array();
}

}  // namespace

std::string RunReport::frames_csv_header() {
  std::string h =
      "frame,timestamp,state,tracked,keyframe,keyframe_reason,point_inliers,line_inliers,reference_tracked,"
      "keyframe_threshold,delta_pid,speed_mps,tracked_close,untracked_close,local_keyframes,local_points,"
      "local_lines,stereo_points,stereo_lines,tracking_ms,map_keyframes,map_points,map_lines,rss_mb";
  static constexpr std::array<const char*, 6> kAxes{"tx", "ty", "tz", "rx", "ry", "rz"};
  for (std::size_t a = 0; a < 6; ++a) {
    for (std::size_t b = a; b < 6; ++b) h += fmt::format(",cov_{}_{}", kAxes[a], kAxes[b]);
  }
  return h;
}

void RunReport::write_frames_csv(std::ostream& out) const {
  out << frames_csv_header() << "\n";
  for (const auto& row : frame_rows) {
    out << fmt::format("{},{:.9f},{},{},", row.frame, row.timestamp, tracking::to_string(row.state),
                       tracking::is_trusted(row.state) ? 1 : 0)
        << row.rest << "\n";
  }
}

void RunReport::settle(const std::vector<tracking::FrameRecord>& records) {
  std::unordered_map<long, tracking::FrameState> settled;
  for (const auto& rec : records) settled[rec.frame_id] = rec.state;
  for (auto& row : frame_rows) {
    const auto it = settled.find(row.frame);
    if (it == settled.end() || it->second == row.state) continue;
    --state_counts[static_cast<std::size_t>(row.state)];
    ++state_counts[static_cast<std::size_t>(it->second)];
    tracked_frames += static_cast<std::size_t>(tracking::is_trusted(it->second)) -
                      static_cast<std::size_t>(tracking::is_trusted(row.state));
    row.state = it->second;
  }
}

void RunReport::add(const FrameResult& r) {
  const auto& in = r.track.keyframe_inputs;
  const auto& d = r.track.decision;
  frame_rows.push_back({r.frame_id, r.timestamp, r.track.frame_state, fmt::format(
      "{},{},{},{},{},{:.2f},{:.2f},{:.3f},{},{},{},{},{},{},{},{:.3f},{},{},{},{:.1f}", r.track.keyframe ? 1 : 0,
      r.track.keyframe ? (r.track.decision.insert ? tracking::to_string(d.reason) : "new-map") : "", r.track.point_inliers, r.track.line_inliers,
      in.reference_tracked, d.threshold, d.delta_pid, d.speed, in.tracked_close, in.untracked_close,
      r.track.local_keyframes, r.track.local_points, r.track.local_lines, r.extraction.stereo_points,
      r.extraction.stereo_lines, r.tracking_ms, r.map_size.keyframes, r.map_size.points, r.map_size.lines, r.rss_mb),
      r.track.pose_covariance});
  const auto& cov = r.track.pose_covariance;
  const bool has_cov = !cov.isZero(0);
  for (int a = 0; a < 6; ++a) {
    for (int b = a; b < 6; ++b) frame_rows.back().rest += has_cov ? fmt::format(",{:.4e}", cov(a, b)) : ",";
  }
  ++frames;
  if (r.track.tracked) ++tracked_frames;
  ++state_counts[static_cast<std::size_t>(r.track.frame_state)];
  tracking_ms.push_back(r.tracking_ms);
  extraction_ms.push_back(r.extraction.extraction_ms);
  stereo_ms.push_back(r.extraction.stereo_ms);
  track_motion_ms.push_back(r.track.times.track_motion_ms);
  track_local_map_ms.push_back(r.track.times.track_local_map_ms);
  pose_optimization_ms.push_back(r.track.times.pose_optimization_ms);
}

nlohmann::json RunReport::to_json(const System& slam) const {
  const auto ms = slam.mapper_stats();
  nlohmann::json pause_wait = summarize(ms.pause_wait_ms);  // loop closing's waits for local mapping
  pause_wait["count"] = ms.pause_wait_ms.size();
  // Local mapping's throughput: keyframes per second of its own busy time (what it could take),
  // and the longest queue it ever had (1: it always kept up).
  double busy_ms = 0;
  for (double t : ms.keyframe_ms) busy_ms += t;
  const nlohmann::json local_mapping = {
      {"keyframes_processed", ms.keyframe_ms.size()},
      {"keyframe_ms", summarize(ms.keyframe_ms)},
      {"keyframes_per_busy_s", busy_ms > 0 ? nlohmann::json(1000.0 * ms.keyframe_ms.size() / busy_ms) : nullptr},
      {"max_queue", ms.max_queue},
      {"local_ba_runs", ms.local_ba_ms.size()},
      {"local_ba_skipped", ms.skipped_local_ba},
      {"local_ba_covered", ms.covered_local_ba},
      {"keyframes_refused_queue_full", slam.tracker().keyframes_refused_queue_full()}};
  // Deterministic mode: where tracking waited for the other threads (timings, like the ms above).
  auto waits = [](const WaitStats& w) {
    return nlohmann::json{{"count", w.count}, {"total_ms", w.total_ms}, {"max_ms", w.max_ms}};
  };
  const nlohmann::json tracking_waits = {{"mapping", waits(slam.mapping_waits())},
                                         {"global_ba_merge", waits(slam.global_ba_waits())}};
  const auto init = slam.initialized_at();
  std::vector<long> lost_ids;
  std::size_t before_init = 0;
  for (const auto& rec : slam.tracker().records()) {
    if (rec.tracked) continue;
    if (init && rec.frame_id > *init) {
      lost_ids.push_back(rec.frame_id);
    } else {
      ++before_init;
    }
  }
  auto suspect_jumps = nlohmann::json::array();
  for (const auto& j : slam.tracker().suspect_jumps()) {
    suspect_jumps.push_back({{"frame", j.frame_id}, {"deviation_m", j.deviation_m}, {"deviation_deg", j.deviation_deg}});
  }
  auto skipped_json = nlohmann::json::array();
  for (const auto& s : skipped) {
    skipped_json.push_back({{"frame", s.index}, {"timestamp", s.timestamp}, {"reason", s.reason}});
  }
  return {{"complete", complete},
          {"mode", slam.options().sequential       ? "sequential"
                   : slam.options().deterministic ? "deterministic"
                                                  : "free-running"},
          {"seed", slam.options().seed},
          {"input_frames", input_frames},
          {"frames", frames},
          {"initialized_at_frame", init ? nlohmann::json(*init) : nlohmann::json(nullptr)},
          {"tracked_frames", tracked_frames},
          {"frame_states", states_json()},
          {"frames_before_initialization", before_init},
          {"lost_frames", lost_ids.size()},
          {"lost_frame_ids", lost_ids},
          {"relocalizations",
           {{"count", slam.tracker().relocalized_frames().size()},
            {"frames", slam.tracker().relocalized_frames()},
            {"refuted", slam.tracker().refuted_relocalizations()}}},
          {"new_map_segments",
           {{"count", slam.tracker().new_segment_frames().size()}, {"frames", slam.tracker().new_segment_frames()}}},
          {"place_recognition",
           slam.keyframe_database()
               ? nlohmann::json{{"enabled", true},
                                {"vocabulary_words", slam.keyframe_database()->vocabulary().size()},
                                {"database_keyframes", slam.keyframe_database()->size()}}
               : nlohmann::json{{"enabled", false}}},
          {"loop_closing", loop_closing_json(slam)},
          {"loops", loops_json(slam)},
          {"loop_correction_ms", loop_correction_ms(slam)},
          {"global_ba_ms", global_ba_ms(slam)},
          {"global_ba_runs", slam.loop_closer() ? slam.loop_closer()->stats().global_ba_runs : 0},
          {"global_ba_aborted", slam.loop_closer() ? slam.loop_closer()->stats().global_ba_aborted : 0},
          {"global_ba_merged_before_frames", slam.global_ba_merge_frames()},
          {"skipped_frames", skipped.size()},
          {"skipped", skipped_json},
          {"untracked_kitti_lines", untracked_lines},
          {"lost_events", slam.tracker().lost_events()},
          {"motion_wide_retries", slam.tracker().motion_wide_retries()},
          {"motion_deviation",
           {{"m", summarize(slam.tracker().motion_deviation_m())}, {"deg", summarize(slam.tracker().motion_deviation_deg())}}},
          {"suspect_jumps", suspect_jumps},
          {"keyframes", slam.map().num_keyframes()},
          {"map_points", slam.map().num_points()},
          {"map_lines", slam.map().num_lines()},
          {"reclaimed",
           {{"runs", slam.reclaim_stats().runs},
            {"points", slam.map().reclaimed().points},
            {"lines", slam.map().reclaimed().lines},
            {"ms", summarize(slam.reclaim_stats().ms)}}},
          {"tracking_ms", summarize(tracking_ms)},
          {"stages_ms",
           {{"extraction", percentile(extraction_ms, 0.5)},
            {"stereo_matching", percentile(stereo_ms, 0.5)},
            {"track_motion", percentile(track_motion_ms, 0.5)},
            {"track_local_map", percentile(track_local_map_ms, 0.5)},
            {"pose_optimization", percentile(pose_optimization_ms, 0.5)}}},
          {"local_ba_ms", {{"median", percentile(ms.local_ba_ms, 0.5)}, {"count", ms.local_ba_ms.size()}}},
          {"mapping_ms",
           {{"keyframe", percentile(ms.keyframe_ms, 0.5)},
            {"triangulation", percentile(ms.triangulation_ms, 0.5)},
            {"fusion", percentile(ms.fusion_ms, 0.5)}}},
          {"local_mapping", local_mapping},
          {"tracking_waits", tracking_waits},
          {"aborted_local_ba", ms.aborted_local_ba},
          {"mapping_pause_wait_ms", pause_wait},
          {"culled_keyframes", ms.culled_keyframes},
          {"triangulated_points", ms.triangulated_points}};
}

nlohmann::json RunReport::states_json() const {
  nlohmann::json j = nlohmann::json::object();
  for (std::size_t i = 0; i < state_counts.size(); ++i) {
    j[tracking::to_string(static_cast<tracking::FrameState>(i))] = state_counts[i];
  }
  return j;
}

std::size_t RunReport::count(tracking::FrameState s) const { return state_counts[static_cast<std::size_t>(s)]; }

std::string RunReport::summary(const System& slam) const {
  using tracking::FrameState;
  return fmt::format(
      "frames {} (tracked {}, skipped {}), lost events {}, relocalizations {}, new map segments {}, loops {}, "
      "keyframes {}, map points {}, map lines {}\n"
      "frame states: tracked {}, relocalized {}, localized {}, recovering {}, unanchored {}, inertial {}, lost {}\n"
      "tracking ms/frame: median {:.1f}, mean {:.1f}, p90 {:.1f}\n",
      frames, tracked_frames, skipped.size(), slam.tracker().lost_events(), slam.tracker().relocalized_frames().size(),
      slam.tracker().new_segment_frames().size(), slam.loop_closer() ? slam.loop_closer()->stats().loops.size() : 0,
      slam.map().num_keyframes(), slam.map().num_points(),
      slam.map().num_lines(), count(FrameState::kTracked), count(FrameState::kRelocalized),
      count(FrameState::kLocalized), count(FrameState::kRecovering), count(FrameState::kUnanchored),
      count(FrameState::kInertial), count(FrameState::kLost),
      percentile(tracking_ms, 0.5), mean(tracking_ms), percentile(tracking_ms, 0.9));
}

nlohmann::json realtime_json(const std::vector<double>& lag_ms, double fps) {
  const double period_ms = fps > 0 ? 1000.0 / fps : 0.0;
  const auto late = std::count_if(lag_ms.begin(), lag_ms.end(), [&](double lag) { return lag > period_ms; });
  return {{"rate_hz", fps}, {"frames", lag_ms.size()}, {"frames_late", late}, {"lag_ms", summarize(lag_ms)}};
}

std::string realtime_summary(const nlohmann::json& realtime) {
  const auto& lag = realtime["lag_ms"];
  if (lag["max"].is_null()) return fmt::format("real time at {:.1f} Hz: no frame processed", realtime["rate_hz"].get<double>());
  return fmt::format("real time at {:.1f} Hz: {} of {} frames late by more than a frame period "
                     "(lag median {:.1f} ms, p90 {:.1f}, max {:.1f})",
                     realtime["rate_hz"].get<double>(), realtime["frames_late"].get<long>(),
                     realtime["frames"].get<long>(), lag["median"].get<double>(), lag["p90"].get<double>(),
                     lag["max"].get<double>());
}

nlohmann::json evaluate_against_ground_truth(const io::Dataset& dataset, const Trajectory& estimate) {
  eval::EvalOptions o;
  o.align = eval::AlignMode::kSE3;
  const auto r = eval::evaluate(*dataset.ground_truth(), estimate, o);
  auto j = eval::to_json(r);
  j["ground_truth"] = dataset.ground_truth_path().string();
  return j;
}

geometry::SE3 shared_world_from_ground_truth(const io::Dataset& dataset) {
  const auto file = dataset.root() / "synth" / "synth.json";
  std::ifstream in(file);
  if (!in) return {};
  nlohmann::json j;
  try {
    j = nlohmann::json::parse(in);
  } catch (const nlohmann::json::exception& e) {
    throw InputError(file.string(), std::string("not JSON: ") + e.what());
  }
  if (!j.contains("world_from_ground_truth")) return {};  // rendered before it was recorded
  const auto& v = j["world_from_ground_truth"];
  if (!v.is_array() || v.size() != 16) throw InputError(file.string(), "world_from_ground_truth: expected 16 numbers");
  Eigen::Matrix4d M;
  for (int r = 0; r < 4; ++r) {
    for (int c = 0; c < 4; ++c) {
      const auto& x = v[static_cast<std::size_t>(r * 4 + c)];
      if (!x.is_number() || !std::isfinite(x.get<double>())) {
        throw InputError(file.string(), "world_from_ground_truth: not a finite number");
      }
      M(r, c) = x.get<double>();
    }
  }
  return geometry::SE3::from_matrix(M);
}

std::optional<geometry::SE3> ground_truth_anchor(const io::Dataset& dataset, const map::KeyFrame& first) {
  if (!dataset.ground_truth() || dataset.ground_truth()->empty()) return std::nullopt;
  const auto& gt = *dataset.ground_truth();
  const auto it = std::min_element(gt.begin(), gt.end(), [&](const StampedPose& a, const StampedPose& b) {
    return std::abs(a.t - first.timestamp()) < std::abs(b.t - first.timestamp());
  });
  if (std::abs(it->t - first.timestamp()) > 0.01) return std::nullopt;
  return shared_world_from_ground_truth(dataset) * geometry::SE3(it->T) * first.pose();
}

nlohmann::json evaluate_in_map_frame(const io::Dataset& dataset, const Trajectory& estimate,
                                     const geometry::SE3& T_shared_map) {
  const Eigen::Isometry3d T_gt_map = (shared_world_from_ground_truth(dataset).inverse() * T_shared_map).isometry();
  Trajectory in_gt = estimate;
  for (auto& p : in_gt) p.T = T_gt_map * p.T;
  eval::EvalOptions o;
  o.align = eval::AlignMode::kNone;
  auto j = eval::to_json(eval::evaluate(*dataset.ground_truth(), in_gt, o));
  j["ground_truth"] = dataset.ground_truth_path().string();
  return j;
}

std::vector<eval::CovariantPose> RunReport::covariant_poses(const Trajectory& trajectory) const {
  std::vector<eval::CovariantPose> out;
  std::size_t row = 0;
  for (const auto& p : trajectory) {
    // Both in processing order: the trajectory's poses are the trusted rows'.
    while (row < frame_rows.size() && frame_rows[row].timestamp < p.t) ++row;
    if (row == frame_rows.size()) break;
    if (frame_rows[row].timestamp == p.t) out.push_back({p.t, geometry::SE3(p.T), frame_rows[row].covariance});
  }
  return out;
}

nlohmann::json motion_nees_json(const io::Dataset& dataset, const std::vector<eval::CovariantPose>& poses) {
  const double period = dataset.fps() > 0 ? 1.0 / dataset.fps() : 0.1;
  const auto r = eval::motion_nees(*dataset.ground_truth(), poses, 1.5 * period);
  return {{"mean", r.mean}, {"median", r.median}, {"motions", r.nees.size()}, {"dof", r.dof}};
}

std::string format_accuracy(const nlohmann::json& a) {
  return fmt::format("ATE (se3) rmse {:.4f} m over {} poses; RPE (1 frame) rmse {:.4f} m, {:.3f} deg\n",
                     a["ape_trans_m"]["rmse"].get<double>(), a["pairs"].get<std::size_t>(),
                     a["rpe_trans_m"]["rmse"].get<double>(), a["rpe_rot_deg"]["rmse"].get<double>());
}

}  // namespace plslam::system
