#pragma once
// The SLAM system: frame extraction, the tracker, and the local mapping thread over one map.
// The caller's thread is the tracking thread; local mapping runs concurrently (or, with
// `sequential`, in the tracking thread after each keyframe, for reproducible runs).
#include <condition_variable>
#include <cstdint>
#include <filesystem>
#include <memory>
#include <mutex>
#include <optional>
#include <thread>
#include <vector>

#include <Eigen/Geometry>

#include "plslam/core/types.h"
#include "plslam/io/dataset.h"
#include "plslam/map/map.h"
#include "plslam/loop/loop_closer.h"
#include "plslam/mapping/local_mapper.h"
#include "plslam/place/keyframe_database.h"
#include "plslam/system/imu_init_monitor.h"
#include "plslam/system/map_file.h"
#include "plslam/tracking/frame_extractor.h"
#include "plslam/tracking/tracker.h"

namespace plslam::system {

struct SystemOptions {
  tracking::FrameExtractorOptions extractor;
  tracking::TrackerOptions tracker;
  mapping::LocalMapperOptions mapper;
  bool sequential = false;
  // The deterministic pipeline, the default (ignored with `sequential`; false: the free-running
  // pipeline, whose threads meet whenever they are done): local mapping and loop closing work on
  // their own thread while the next frame's features are extracted, and tracking waits for them
  // before it reads the map; the global BA optimises beside both and is merged at a frame fixed in
  // advance (loop.global_ba_merge_after_s). Runs are identical to each other, and with a one-frame
  // lag (mapping.ba_merge_after_frames 1, ba_merge_ms_per_1000_observations 0) to --sequential's
  // up to the first loop; see the README ("How the threads meet").
  bool deterministic = true;
  // Seed of every random choice (config `system.seed`, recorded in stats.json): the PnP RANSAC
  // of relocalization (geometry::PnpOptions::seed). Tracking, mapping and BA make none.
  std::uint32_t seed = 1;
  // Place recognition (config `place`): the vocabulary of the keyframe database that
  // relocalization queries; empty: the default vocabulary shipped in data/.
  bool place_recognition = true;
  std::filesystem::path vocabulary;
  // Loop closing (config `loop`, --no-loop-closing): needs place recognition.
  bool loop_closing = true;
  loop::LoopClosingOptions loop;
  // Localization in a loaded map (--localize): no keyframes, points or lines are added, and
  // neither local mapping nor loop closing runs.
  bool localization_only = false;
  // With an IMU (set_imu): once it is initialised, tracking predicts and optimises with it and
  // local BA keeps the IMU's factors (stereo-inertial). false: the IMU only turns the world to
  // gravity (stereo).
  bool visual_inertial = true;
  // Config imu.enabled: false leaves an input's IMU unused in `plslam run`, as --no-imu does
  // (stereo only, the world the first camera's; bench slam's `stereo` configuration).
  bool use_input_imu = true;
  // Input seconds after the turn to stereo-inertial at which a global BA with the IMU factors
  // refines gravity's direction, the keyframes' velocities and the biases over the whole map
  // (ORB-SLAM3's VIBA 1 and 2): the initialisation saw a few seconds of motion, in which gravity's
  // tilt and an accelerometer bias look alike. 0: not. Needs loop closing (its global BA).
  double imu_refine_after_s = 5;
  double imu_refine_again_after_s = 15;

  static SystemOptions euroc();
  static SystemOptions kitti();
  // Switches lines off everywhere (--no-lines).
  void disable_lines();
};

// How long tracking waited for the other threads at the points where they meet (deterministic
// mode): a frame whose wait exceeded 0.1 ms counts.
struct WaitStats {
  int count = 0;
  double total_ms = 0;
  double max_ms = 0;
  void add(double ms);
};

struct FrameResult {
  long frame_id = 0;      // the frame's index in the input
  double timestamp = 0;   // seconds
  tracking::TrackResult track;
  tracking::FrameTimings extraction;
  double tracking_ms = 0;  // images in to pose out
  // A tracked frame's pose (T_world_leftcam): from its reference keyframe as the map holds it when
  // process() returns, except in deterministic mode, where local mapping may still be moving that
  // keyframe then: there as tracking left it, before the keyframe's local mapping.
  std::optional<Eigen::Isometry3d> T_world_camera;
  // After the frame (and any reclamation it triggered; in deterministic mode, before the frame's
  // keyframe is mapped): the map's size and the process's resident memory (-1 where unknown), to
  // see memory and map growth over long runs.
  map::Map::Sizes map_size;
  double rss_mb = -1;
};

class System {
 public:
  // Without a vocabulary there is no place recognition: a lost camera starts a new map segment.
  System(const StereoCalibration& calib, SystemOptions options,
         std::shared_ptr<const place::Vocabulary> vocabulary = nullptr);
  ~System();
  System(const System&) = delete;
  System& operator=(const System&) = delete;

  FrameResult process(const io::StereoFrame& frame);
  // Lets local mapping finish its queue and stops it. Outputs are final after this.
  void finish();

  // Before the first frame: takes the map of a map file (check_map_matches first); the first
  // frame is then relocalized in it. Throws std::logic_error after the first frame.
  void load_map(const MapContents& contents);
  // The map as a map file holds it (after finish()); meta's calibration and vocabulary identity
  // are filled in here.
  MapContents capture_map(MapFileMeta meta) const;

  // Before the first frame: the input's IMU (a copy). Visual-inertial initialisation is tried on
  // the tracked frames (ImuInitMonitor); once accepted, the world turns to the gravity-aligned one
  // (z up, origin and yaw still the first keyframe's camera's) at the next frame boundary where no
  // other thread works on the map: every keyframe, point, line and tracked pose, so that all
  // outputs (also of the frames before) are in it. A loaded map keeps its world: the IMU is then
  // only initialised and reported. Not with localization_only. Throws std::logic_error after the
  // first frame.
  void set_imu(const ImuData& imu, ImuInitMonitorOptions options = {});
  // Null without an IMU.
  const ImuInitMonitor* imu_init() const { return imu_init_ ? &*imu_init_ : nullptr; }
  // The rotation applied to the world (x_gravity = R x_first_camera) and the first frame whose
  // FrameResult pose is in the turned world; nullopt while not turned.
  struct GravityAlignment {
    Eigen::Matrix3d R_new_old = Eigen::Matrix3d::Identity();
    long from_frame = -1;
  };
  const std::optional<GravityAlignment>& gravity_alignment() const { return gravity_alignment_; }
  // stats.json's "imu": the monitor's report and the world's alignment; null without an IMU.
  nlohmann::json imu_report() const;
  // One log line: stereo or stereo-inertial, from which frame, and the final bias estimates.
  std::string imu_summary() const;
  // The last keyframe's estimated biases (a stereo-inertial run), else nothing.
  std::optional<inertial::ImuBias> final_imu_bias() const;

  // The trusted frames only (tracking::is_trusted: never a prediction made while lost or before
  // initialisation, nor a pose recovering from an unconfirmed relocalization), T_world_leftcam with
  // world = the first keyframe's camera, or its gravity-aligned turn (set_imu()).
  Trajectory tracked_trajectory() const;
  // The id of the first frame that started a map; nullopt while none has.
  std::optional<long> initialized_at() const;
  Trajectory keyframe_trajectory() const;
  const map::Map& map() const { return map_; }
  const SystemOptions& options() const { return options_; }
  const tracking::Tracker& tracker() const { return *tracker_; }
  // Null without place recognition.
  const place::KeyframeDatabase* keyframe_database() const { return database_.get(); }
  mapping::LocalMapperStats mapper_stats() const { return mapper_->stats(); }
  // Null without loop closing.
  const loop::LoopCloser* loop_closer() const { return loop_closer_.get(); }
  // How often culled points and lines were freed (Map::reclaim; the totals: map().reclaimed()),
  // and the time each took in tracking's thread.
  struct ReclaimStats {
    int runs = 0;
    std::vector<double> ms;
  };
  const ReclaimStats& reclaim_stats() const { return reclaim_stats_; }
  // Deterministic mode: the waits for local mapping and loop closing, and for a global BA's merge.
  const WaitStats& mapping_waits() const { return mapping_waits_; }
  const WaitStats& global_ba_waits() const { return global_ba_waits_; }
  // Deterministic mode: the frames before which a global BA was merged (one merged at the end of
  // the run is not listed).
  const std::vector<long>& global_ba_merge_frames() const { return global_ba_merge_frames_; }

 private:
  // Frees the culled points and lines when every thread is at rest: tracking between frames,
  // local mapping and loop closing idle (held paused meanwhile), no global BA. At most once per
  // new keyframe; when a thread is busy, a later frame does it.
  void reclaim_culled();
  // After a relocalization in the same map, asks loop closing for a global BA at the next keyframe.
  void note_revisit(const tracking::TrackResult& track);
  // The first keyframe at or after a due inertial refinement asks loop closing for it.
  void note_inertial_refinement(const tracking::TrackResult& track, double timestamp);
  // Deterministic mode. start_mapping_job() maps what the frame queued in mapping_job_: it first
  // finishes the keyframe before (its local BA's result, keyframe culling, loop closing), then
  // edits the map for the new one and, once the edits are done (wait_for_map_edits(), before the
  // next frame is tracked), optimises its local BA beside tracking. finish_local_ba() joins the
  // job and finishes its keyframe in the caller, at the frame mapping.ba_merge_after_frames fixes.
  void start_mapping_job(long frame_id, double timestamp);
  void wait_for_map_edits();
  void finish_local_ba();
  // The local BA in flight is due at this frame (its frame and input time have come).
  bool local_ba_due(long frame_id, double timestamp) const;
  // The local BA due at this frame is finished in mapping_job_ while the frame's features are
  // extracted (its result, keyframe culling, the hand-over to loop closing: 3 ms of tracking's
  // time on the street loop); the meeting point joins it. Not at lag 1 (its due time is unknown).
  void finish_due_local_ba_beside_extraction(long frame_id, double timestamp);
  // Loop closing in deterministic mode: detection and verification of the keyframes mapping
  // finished (start_loop_job()) run beside tracking until the next meeting point (join_loop_job(),
  // or the next job before its edits); what they found is done at the meeting points
  // (run_loop_closing_steps()): a verified loop's correction begins there, its essential graph is
  // solved beside tracking, and it ends loop.correction_merge_after_frames later; a global BA a
  // revisit asked for starts there.
  void start_loop_job();
  void join_loop_job();
  void run_loop_closing_steps(long frame_id);
  bool correction_open() const;  // a loop correction has begun and not ended
  // What note_revisit() and note_inertial_refinement() kept for a meeting point (the global BAs they
  // ask for), handed to loop closing (needs loop_closer_).
  void tell_loop_closing_of_requests();
  // Deterministic mode: fixes the merge frame of a global BA that started, and merges it there.
  void merge_due_global_ba(long frame_id, double timestamp);
  bool deterministic() const;
  // Turns the world to the accepted initialisation's gravity-aligned one (set_imu()) if every
  // other thread is at rest: local mapping and loop closing idle and held paused, no global BA.
  // `frame_id`: the first frame tracked in the turned world. A loaded gravity-aligned map is not
  // turned: the run goes stereo-inertial in it if the two up directions agree.
  void align_world_with_gravity(long frame_id);
  // Tracking, local mapping and loop closing use the IMU from here on (options_.visual_inertial).
  void start_visual_inertial();

  SystemOptions options_;
  map::Map map_;
  tracking::FrameExtractor extractor_;
  std::unique_ptr<place::KeyframeDatabase> database_;
  std::unique_ptr<mapping::LocalMapper> mapper_;
  std::unique_ptr<loop::LoopCloser> loop_closer_;
  std::unique_ptr<tracking::Tracker> tracker_;
  StereoCalibration calib_;
  bool finished_ = false;
  long reclaimed_at_keyframe_ = 0;  // map_.next_ids().keyframe at the last reclamation
  bool tracked_before_ = false;     // some frame of this run was tracked
  long trusted_reference_ = -1;  // reference keyframe of the last trusted frame (not a relocalized one)
  long revisit_from_ = -1;       // ... when the pending revisit's relocalization came
  bool revisit_pending_ = false;  // relocalized after a loss; its first keyframe asks for a global BA
  ReclaimStats reclaim_stats_;
  std::thread mapping_job_;
  std::mutex job_mutex_;
  std::condition_variable job_cv_;
  bool job_edits_done_ = true;  // guarded by job_mutex_
  bool ba_in_flight_ = false;   // mapping_job_ holds a keyframe that finish_local_ba() must finish
  long ba_due_frame_ = -1;      // ... before this frame is tracked
  double ba_due_time_ = -1;     // ... and before the first frame of this input time (window size)
  double job_timestamp_ = 0;    // the input time of the frame whose keyframe the job maps
  std::size_t job_ba_observations_ = 0;  // its BA window's observations; guarded by job_mutex_
  std::thread loop_job_;        // loop closing's detection and verification, beside tracking
  long correction_due_frame_ = -1;  // an open loop correction ends before this frame is tracked
  long steps_due_frame_ = -1;  // loop closing's steps wait for a frame with no local BA in flight, until this one
  std::optional<std::pair<long, long>> revisit_for_loop_closing_;  // global_ba_after_keyframe's arguments
  std::optional<long> refinement_for_loop_closing_;  // refine_inertial_after_keyframe's argument
  std::vector<double> inertial_refinements_due_;    // input times, ascending
  long seen_global_ba_starts_ = 0;
  double last_timestamp_ = 0;       // the last frame's input time
  double global_ba_merge_at_ = -1;  // input time of the pending global BA's merge (-1: none)
  WaitStats mapping_waits_;
  WaitStats global_ba_waits_;
  std::vector<long> global_ba_merge_frames_;
  bool map_loaded_ = false;
  bool loaded_map_gravity_aligned_ = false;  // the loaded map file says its z axis is up
  // A gravity-aligned loaded map met this run's IMU initialisation: how far the two up directions
  // were apart, and from which frame. Within kMaxLoadedMapTiltDeg (the initialisation's gravity
  // is within ~0.5 deg, the map's too) the run goes stereo-inertial in the map's world as it is.
  struct LoadedMapImu {
    double tilt_deg = 0;
    long from_frame = 0;
  };
  static constexpr double kMaxLoadedMapTiltDeg = 2.0;
  std::optional<LoadedMapImu> loaded_map_imu_;
  std::optional<ImuData> imu_data_;  // the monitor refers to it
  std::optional<ImuInitMonitor> imu_init_;
  std::optional<GravityAlignment> gravity_alignment_;
};

}  // namespace plslam::system
