#pragma once
// What `plslam run` reports: per-frame timings and counts gathered during the run, turned into
// stats.json and a short summary; and the accuracy against the dataset's ground truth.
#include <array>
#include <optional>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "plslam/eval/motion_nees.h"
#include "plslam/io/dataset.h"
#include "plslam/io/frame_stream.h"
#include "plslam/system/slam_system.h"

namespace plslam::system {

struct RunReport {
  std::vector<double> tracking_ms, extraction_ms, stereo_ms, track_motion_ms, track_local_map_ms,
      pose_optimization_ms;
  std::size_t frames = 0;
  std::size_t tracked_frames = 0;  // frames with a trusted pose (tracking::is_trusted)
  std::array<std::size_t, tracking::kFrameStates> state_counts{};  // frames per tracking::FrameState
  std::size_t input_frames = 0;            // frames the input holds (the selected range)
  std::vector<io::SkippedFrame> skipped;   // unreadable or blank frames, left out
  std::vector<std::size_t> untracked_lines;  // input frames whose trajectory.kitti line is not tracked
  bool complete = false;                   // every input frame was reached
  // frames.csv, one row per processed frame: its state, and the columns after state and tracked.
  struct FrameRow {
    long frame = 0;
    double timestamp = 0;
    tracking::FrameState state = tracking::FrameState::kLost;
    std::string rest;
    geometry::Matrix6d covariance = geometry::Matrix6d::Zero();  // tracking::TrackResult::pose_covariance
  };
  std::vector<FrameRow> frame_rows;

  void add(const FrameResult& r);
  // After System::finish(): the states as the tracker settled them (Tracker::settle_states: a
  // segment a loop tied to the map), in the rows and the counts.
  void settle(const std::vector<tracking::FrameRecord>& records);
  // frames.csv: per frame, what tracking saw and decided (inliers, the keyframe rule's inputs,
  // local map size, stereo features, time), to find where and why a run's error grows.
  // The last 21 columns, cov_tx_tx ... cov_rz_rz, are the upper triangle of the pose's covariance
  // (tracking::TrackResult::pose_covariance; m^2, m rad, rad^2), empty where the frame has none.
  static std::string frames_csv_header();
  void write_frames_csv(std::ostream& out) const;
  // Counts and ids of the frames tracked, lost, before initialisation and skipped (from the
  // tracker's records), timings, and the map's size.
  nlohmann::json to_json(const System& slam) const;
  std::string summary(const System& slam) const;
  std::size_t count(tracking::FrameState s) const;
  nlohmann::json states_json() const;  // {"lost": n, "recovering": n, ...}
  // The trajectory's poses with their frames' covariances (eval::motion_nees), by timestamp.
  std::vector<eval::CovariantPose> covariant_poses(const Trajectory& trajectory) const;
};

// `plslam run --realtime`: how far behind real time the run fell. lag_ms holds, per frame, how
// late its processing started after the time the frame was due (0 when on time). A frame is late
// when it starts more than one frame period (1/fps) after it was due: a live camera would have
// delivered the next frame by then. {rate_hz, frames, frames_late, lag_ms: {median, p90, mean, max}}.
nlohmann::json realtime_json(const std::vector<double>& lag_ms, double fps);
// One line for the log: "real time at 20.0 Hz: 3 of 480 frames late (...)".
std::string realtime_summary(const nlohmann::json& realtime);

// ATE (se3 alignment) and RPE (1 frame) of the trajectory against the dataset's ground truth,
// through the eval library.
nlohmann::json evaluate_against_ground_truth(const io::Dataset& dataset, const Trajectory& estimate);
std::string format_accuracy(const nlohmann::json& accuracy);
// The mean NEES of the frame-to-frame motions of `poses` (trusted, with covariances) against the
// dataset's ground truth, pairs at most 1.5 frame periods apart: {mean, median, motions, dof}.
nlohmann::json motion_nees_json(const io::Dataset& dataset, const std::vector<eval::CovariantPose>& poses);

// The frame that ground truths of different sequences share, from the dataset's ground-truth
// frame: a rendered sequence records its scene's world (synth/synth.json,
// "world_from_ground_truth"; KITTI's ground truth starts at each sequence's first camera);
// identity for any other dataset, whose ground truth is taken to be its own world.
geometry::SE3 shared_world_from_ground_truth(const io::Dataset& dataset);
// The map's world in that shared frame (MapFileMeta::T_gt_map): the ground-truth pose at the
// first keyframe's time composed with that keyframe's pose; nullopt without ground truth there.
std::optional<geometry::SE3> ground_truth_anchor(const io::Dataset& dataset, const map::KeyFrame& first);
// Position errors of a trajectory expressed in a loaded map's world, taken into this dataset's
// ground-truth frame through the anchor and compared with NO alignment: {pairs, ape_trans_m, ...}.
nlohmann::json evaluate_in_map_frame(const io::Dataset& dataset, const Trajectory& estimate,
                                     const geometry::SE3& T_gt_map);

}  // namespace plslam::system
