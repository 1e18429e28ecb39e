#pragma once
// The tracking thread's work for one frame (ORB-SLAM2's Tracking, with lines): stereo
// initialisation, constant-velocity motion model with projection search, fall-back to the
// reference keyframe, local map tracking, pose-only optimisation over points and lines, the
// keyframe decision (PID + Kalman), and keyframe creation with new stereo points and lines.
#include <cstdint>
#include <functional>
#include <memory>
#include <optional>
#include <vector>

#include "plslam/core/imu.h"
#include "plslam/core/pointer_set.h"
#include "plslam/geometry/se3.h"
#include "plslam/inertial/inertial_pose.h"
#include "plslam/map/map.h"
#include "plslam/optim/pose_only.h"
#include "plslam/tracking/frame.h"
#include "plslam/tracking/keyframe_policy.h"
#include "plslam/tracking/projection_search.h"

namespace plslam::place {
class KeyframeDatabase;
}  // namespace plslam::place

namespace plslam::tracking {

// Relocalization while LOST (ORB-SLAM2's Relocalization, with lines): keyframes that look like the
// frame (keyframe database), BoW matching, PnP RANSAC, pose optimisation over points and lines,
// search by projection, and an inlier threshold.
struct RelocalizationOptions {
  bool enabled = true;             // also needs a keyframe database (a vocabulary)
  std::size_t max_candidates = 10; // keyframes tried per frame, best place first
  int min_bow_matches = 15;        // BoW matches a candidate needs before PnP
  int min_pnp_inliers = 10;
  double search_radius = 3.0;      // factor of the local-map search window, around the PnP pose
  int search_covisibles = 10;      // the candidate's best covisibles whose landmarks are searched too
  int min_inliers = 50;            // point + line inliers to accept (ORB-SLAM2: 50 points)
  // ... and matches to at least this share of the candidate neighbourhood's map points that are
  // visible from the pose found: a look-alike place matches only what repeats.
  double min_found_ratio = 0.15;
  // A camera that stays lost this long on frames that could start a map (seconds of textured
  // frames, so a black-out does not count) starts a new map segment instead.
  double new_segment_after_s = 1.0;
  // A camera cannot have moved further than max_speed times the time since it was last tracked,
  // plus gate_margin metres: a pose beyond that is another place that looks the same (a row of
  // identical windows, desks or shelves) and the next candidate is tried. 0: no gate. Before the
  // first tracked frame (a loaded map) there is no gate: the camera may be anywhere.
  double max_speed = 0;     // m/s
  double gate_margin = 1.0; // m
  // A relocalization is trusted only after this many frames in a row, the relocalizing one
  // included, were tracked from it, each matching at least min_found_ratio of the local map points
  // visible from its pose and moving as the motion model (or max_speed) allows, and once the
  // camera has moved confirm_distance_m or turned confirm_angle_deg from the relocalized pose (0
  // and 0: no such condition). Until then the frames are `recovering`: their poses are not
  // reported as trusted and no keyframe is made. A look-alike place (a shelf with the same books
  // on its other face) can pass every check of one frame, but its repeated part leaves the view as
  // the camera moves on. 1: trusted at once.
  int confirm_frames = 1;
  double confirm_distance_m = 0;
  double confirm_angle_deg = 0;
  // ... and every recovering frame has inliers in at least this share of the image cells where
  // the local map shows points (tracking::cell_coverage): a look-alike is matched only on the
  // repeated object. 0: no such check.
  double min_cell_coverage = 0;
  // ... except that this many recovering frames under min_cell_coverage (a miss) are forgiven, each
  // after at least two frames that held it and at the price of one more such frame before the
  // confirmation: a true place seen at the map's edge or across a turn can dip below the threshold
  // for a frame (0.743 on the office, between 0.88 and 0.84 frames), where a look-alike fails most of
  // its frames. 0: every miss refutes.
  int max_cell_misses = 0;
  // A relocalization within this many seconds of the last trusted frame, with only lost frames
  // between them, whose pose lies within tracking.jump_deviation_m/_deg of where the motion model
  // carries that frame, continues the trusted trajectory: it is confirmed at once. A look-alike
  // place metres away never lands on the prediction. 0: never.
  double continuity_s = 0;
};

// Tracking with the IMU, once the map is gravity-aligned (Tracker::use_imu).
struct ImuTrackingOptions {
  // Keyframes of the IMU chain started at use_imu(): the last ones, their velocities estimated from
  // their positions until local BA (LocalMapperOptions::imu_window) or a global BA settles them.
  // 0: every keyframe of the current segment, as ORB-SLAM3 makes every keyframe of the map
  // inertial at its initialisation: a global BA after a loop then has the IMU's factors from the
  // first keyframe on, where the camera was tracked without them.
  int seed_keyframes = 0;
  // A keyframe is due once the last one is this old: preintegration stays short (ORB-SLAM3: 0.5 s).
  double max_keyframe_interval_s = 0.5;
  // The IMU predicts from the newest keyframe of the chain whose state a local BA estimated
  // (map::KeyFrameImu::estimated), if it is at most this much older than the frame. Long enough
  // for a black-out of max_inertial_s after a keyframe's interval (ORB-SLAM3 keeps a recently
  // lost camera on the IMU for 5 s): a 3 s black-out then rejoins the map.
  double max_prediction_s = 5.0;
  // Only a frame with fewer stereo points than this (a black or blurred image, a covered lens) is
  // carried by the IMU when vision fails; a textured frame vision cannot track is lost, as without
  // an IMU (its failure is no lack of texture, and the IMU cannot tell what else went wrong).
  int max_texture_points = 50;
  // A frame that vision cannot track (a black or blurred image, a covered lens) takes the IMU's
  // prediction, state `inertial`, for at most this long after the last frame vision tracked;
  // then the camera is lost, as without an IMU.
  double max_inertial_s = 4.0;
  // A textured frame that vision cannot place in the map within max_inertial_s of the last frame
  // it tracked, where the map shows little from the IMU's pose (a black-out or a fast turn ended
  // facing what the map has not seen): a keyframe at the IMU's pose starts mapping that view, in
  // the same map and IMU chain, state `inertial`. Where the map shows at least
  // new_view_max_visible_points there, the frame is lost instead: the view is not new, so the
  // IMU's pose or the images are wrong.
  bool map_new_views = true;
  int new_view_max_visible_points = 60;
};

struct TrackerOptions {
  int init_min_points = 500;          // stereo points needed to start a map
  double close_depth_baselines = 40;  // "close" stereo points: depth < 40 baselines (ORB-SLAM2)
  // Right-image matches of points beyond this depth (baselines) are not optimisation constraints
  // (map::FrameData::stereo_constraint); 0: all are.
  double far_stereo_baselines = 0;
  int new_keyframe_points = 100;      // a keyframe creates at least this many points (closest first)
  double motion_radius = 7.0;         // px at level 0, motion-model search (ORB-SLAM2 stereo)
  double local_map_radius = 1.0;      // px factor, local-map search (times 2.5 or 4 and the level scale)
  double line_radius = 8.0;           // px, line search
  // Motion-model tracking searches again in windows `motion_retry_scale` times wider when fewer
  // than this share of its matches survive the pose optimisation (the motion changed suddenly).
  double motion_min_inlier_share = 0.5;
  // ... or when its matches fall below this share of the last frame's tracked points: a sudden
  // turn moved most of them out of the windows. In a concurrent run, where local mapping lags in a
  // fast turn, the few left (27 of 210 once, on the office loop's corner) then gave a pose 1.8 deg
  // off that the next frames built on.
  double motion_min_match_share = 0.3;
  double motion_retry_scale = 4.0;
  // A tracked pose further than this from the constant-velocity prediction (camera centre, or
  // rotation) is a suspect jump: tracking may have settled on a look-alike place that the
  // following frames then agree with. It is reported (warning, stats.json suspect_jumps), never
  // silently kept. The pose is kept when it matches at least relocalization.min_found_ratio of
  // the local map points visible from it; otherwise it is a look-alike and the frame counts as
  // lost (it is relocalized at once). 0: no check. The largest deviations of good runs, on
  // the real excerpts and the rendered office, corridor and street loop (concurrent and
  // sequential): 0.15 m and 1.3 deg (a car on the street loop); a look-alike corner once gave 1 m
  // and 12 deg.
  double jump_deviation_m = 0.5;
  // A frame tracked more than this many seconds after the frame before it (a black-out, frames
  // skipped as unreadable) is not trusted at once: it recovers as a relocalization does
  // (RelocalizationOptions::confirm_frames and its checks). 0: never.
  double recover_after_gap_s = 0;
  double jump_deviation_deg = 10.0;
  int min_motion_matches = 20;
  int min_pose_inliers = 10;
  int min_local_inliers = 30;
  // Tracking against the reference keyframe (no motion model): descriptor matches to its map
  // points that pass this ratio test, at least `min_reference_matches` of them, and PnP RANSAC
  // from them as a second start when there are at least `min_pnp_matches`.
  double reference_match_ratio = 0.75;
  int min_reference_matches = 15;
  int min_pnp_matches = 15;
  int local_map_covisibles = 10;  // best covisibles of each keyframe that sees a match join the local map
  bool lines = true;
  double line_information = 0.5;      // the paper's line information
  SearchOptions search;
  optim::PoseOnlyOptions pose;
  KeyframePolicyOptions keyframe;
  int local_keyframes_max = 80;
  RelocalizationOptions relocalization;
  ImuTrackingOptions imu;
  std::uint32_t seed = 1;  // of the relocalization's PnP RANSAC (SystemOptions::seed)
  // Localization in a loaded map: no keyframe is created and a lost camera never starts a new
  // map segment; it waits for relocalization instead.
  bool localization_only = false;
};

enum class TrackingState { kNotInitialized, kOk, kLost };
const char* to_string(TrackingState s);

// What a frame's pose is worth (frames.csv `state`, the API's frame_state):
//   tracked      tracked from the frames before it (or it started a map): trusted;
//   recovering   tracked from a relocalization not yet confirmed: a pose, but not trusted;
//   relocalized  the frame that confirmed a relocalization: trusted;
//   localized    tracked in a loaded map, localization only (--localize): trusted;
//   lost         no pose (lost, or before the map started);
//   inertial     vision could not track it (no texture): the IMU carried the pose from the last
//                keyframe, for a few seconds at most (ImuTrackingOptions::max_inertial_s): trusted;
//   unanchored   tracked in a new map segment that no loop has tied to the map yet: right
//                relative to the segment's other frames, but the segment's place in the map is
//                the motion model's guess across the loss. Not trusted; the run's outputs count
//                it tracked if a loop ties the segment before the end (Tracker::settle_states).
enum class FrameState { kLost, kRecovering, kRelocalized, kTracked, kLocalized, kUnanchored, kInertial };
const char* to_string(FrameState s);
// The states whose pose plslam stands behind (trajectory.tum holds only these).
constexpr bool is_trusted(FrameState s) {
  return s != FrameState::kLost && s != FrameState::kRecovering && s != FrameState::kUnanchored;
}
constexpr int kFrameStates = 7;

struct TrackStageTimes {
  double track_motion_ms = 0;     // motion model or reference keyframe, search + optimisation
  double track_local_map_ms = 0;  // local map search + optimisation
  double pose_optimization_ms = 0;  // the optimisations alone (part of the two above)
};

struct TrackResult {
  TrackingState state = TrackingState::kNotInitialized;
  FrameState frame_state = FrameState::kLost;
  // The frame has a trusted pose (is_trusted(frame_state)): it initialised a map or was tracked
  // in one, and is not recovering from an unconfirmed relocalization.
  bool tracked = false;
  int point_inliers = 0;
  int line_inliers = 0;
  // Of the pose (when the frame has one and its final optimisation observed every direction):
  // optim::PoseOnlyResult::covariance, the camera's pose error in its own frame, (translation,
  // rotation). Zero otherwise.
  geometry::Matrix6d pose_covariance = geometry::Matrix6d::Zero();
  bool keyframe = false;
  bool relocalized = false;      // confirmed a relocalization (FrameState::kRelocalized)
  bool new_map_segment = false;  // a lost camera started a new, disconnected map segment
  long relocalized_against = -1; // the keyframe (id) relocalization matched (on the relocalizing frame)
  KeyframeDecision decision;
  KeyframeInputs keyframe_inputs;  // what the decision saw (tracked frames only)
  int local_keyframes = 0, local_points = 0, local_lines = 0;  // the local map tracked against
  TrackStageTimes times;
};

// A tracked frame whose pose deviates from the motion model's prediction by more than
// TrackerOptions::jump_deviation_m or _deg.
struct SuspectJump {
  long frame_id = 0;
  double deviation_m = 0;    // camera centre, tracked vs predicted
  double deviation_deg = 0;  // rotation, tracked vs predicted
};

// One row per processed frame: its pose is T_cr · T_rw, relative to its reference keyframe, so
// it follows the keyframe when bundle adjustment moves it (ORB-SLAM2's trajectory bookkeeping).
struct FrameRecord {
  long frame_id = 0;
  double timestamp = 0;
  map::KeyFrame* reference = nullptr;
  geometry::SE3 T_cr;
  bool tracked = false;  // has a pose estimate (trusted or recovering)
  FrameState state = FrameState::kLost;
  bool trusted() const { return is_trusted(state); }
};

class Tracker {
 public:
  // `insert_keyframe` hands a new keyframe to local mapping; `mapping_idle` tells whether local
  // mapping accepts keyframes right now.
  Tracker(map::Map& map, TrackerOptions options, std::function<void(map::KeyFrame*)> insert_keyframe,
          std::function<bool()> mapping_idle);

  TrackResult track(std::shared_ptr<const map::FrameData> data);
  // The map is gravity-aligned (z up, the IMU initialised with `bias`): the last
  // options.imu.seed_keyframes keyframes (0: all) start the IMU chain (map::KeyFrameImu), and from the
  // next frame on, once local BA has estimated the last keyframe's velocity, the IMU predicts each
  // frame from it and the pose optimisation adds the IMU's residual (inertial/inertial_pose.h).
  // `imu` is not owned and must outlive the tracker.
  void use_imu(const ImuData& imu, const inertial::ImuBias& bias);
  bool imu_on() const { return imu_ != nullptr; }
  // Frames tracked with the IMU's residual, and frames the IMU carried alone (state inertial).
  int imu_tracked_frames() const { return imu_tracked_frames_; }
  int inertial_frames() const { return inertial_frames_; }
  // Of those, the keyframes that started mapping a view the map lacked (map_new_views).
  int new_views_from_imu() const { return new_views_from_imu_; }
  // Whether a frame at time t that vision cannot use (a blank image) would now take the IMU's pose
  // (state inertial): tracking is on, with the IMU's prediction, within max_inertial_s of the last
  // frame vision tracked. plslam run passes its blank frames to tracking only then.
  bool can_carry_by_imu(double t) const;
  // Place recognition for relocalization; without one, a lost camera starts a new map segment on
  // the next frame that can. Not owned; must outlive the tracker.
  void set_keyframe_database(const place::KeyframeDatabase* database) { database_ = database; }
  // The map was loaded from a file: the first frame is relocalized in it instead of starting a
  // map (call before the first frame). Its keyframes stay out of this run's IMU chain.
  void start_in_loaded_map();

  int lost_events() const { return lost_events_; }
  // Motion-model searches repeated in the wide windows (a low inlier share or few matches).
  int motion_wide_retries() const { return motion_wide_retries_; }
  // Per frame tracked with a velocity: how far its pose landed from the prediction.
  const std::vector<double>& motion_deviation_m() const { return motion_deviation_m_; }
  const std::vector<double>& motion_deviation_deg() const { return motion_deviation_deg_; }
  const std::vector<SuspectJump>& suspect_jumps() const { return suspect_jumps_; }
  // Keyframes not made because local mapping's queue was full (KeyframePolicyOptions::max_queued).
  int keyframes_refused_queue_full() const { return keyframes_refused_queue_full_; }
  // How many keyframes wait for local mapping (KeyframeInputs::keyframes_queued); none when unset.
  void set_mapping_queue(std::function<std::size_t()> queued) { mapping_queue_ = std::move(queued); }
  // Forgets the culled points and lines it keeps between frames (the last frame's matches, the
  // local map), so that Map::reclaim() can free them; call between frames.
  void drop_bad_landmarks();
  // Confirmed relocalizations, by the frame that relocalized (RelocalizationOptions::confirm_frames).
  const std::vector<long>& relocalized_frames() const { return relocalized_frames_; }
  // Relocalizations that a later frame refuted before confirmation: the frames that relocalized.
  const std::vector<long>& refuted_relocalizations() const { return refuted_relocalizations_; }
  const std::vector<long>& new_segment_frames() const { return new_segment_frames_; }
  const std::vector<FrameRecord>& records() const { return records_; }
  // At the end of a run: the frames of a segment that a loop tied to the map after they were
  // tracked become tracked (their poses follow their reference keyframes into the map's frame),
  // and the frames the IMU carried alone are smoothed between their two ends.
  void settle_states();
  // The ids of the local map the last frame was tracked against (the live viewer highlights it);
  // tracking thread, between frames.
  std::vector<long> local_keyframe_ids() const;
  std::vector<long> local_point_ids() const;
  // Where the last frame's matched (inlier) points and lines lie in its left image, to draw them.
  struct TrackedFeatures {
    std::vector<cv::Point2f> points;
    std::vector<std::pair<cv::Point2f, cv::Point2f>> lines;
  };
  TrackedFeatures last_tracked_features() const;
  // The map was re-expressed in another world (map::Map::transform_world): the world poses the
  // tracker keeps across frames follow it (the last frame, an unconfirmed relocalization, records
  // without a reference keyframe). Between frames.
  void transform_world(const geometry::SE3& T_new_old);
  // The pose of a record with every keyframe's current estimate (call with local mapping idle).
  static geometry::SE3 pose_of(const FrameRecord& r);
  // The keyframe a record's pose hangs on (its reference, or the first live ancestor of a culled
  // one) and the frame's pose relative to it; nullptr and T_cr for a record without one.
  struct Anchor {
    const map::KeyFrame* keyframe = nullptr;
    geometry::SE3 T_ck;
    geometry::SE3 T_cw() const;  // with the keyframe's current pose
  };
  static Anchor anchor_of(const FrameRecord& r);

 private:
  bool initialize(Frame& f);
  // The IMU's prediction of the frame being tracked, from the last keyframe's estimated state
  // (tracker_inertial.cpp).
  struct ImuPrior {
    const map::KeyFrame* keyframe = nullptr;  // the estimated keyframe it predicts from
    inertial::InertialState from;  // the keyframe's
    std::shared_ptr<const inertial::Preintegration> pim;  // keyframe -> frame
    inertial::InertialState predicted;
    geometry::SE3 T_cw;  // the camera's predicted pose
  };
  std::optional<ImuPrior> imu_prior(double t) const;
  // The IMU state a keyframe made from `f` starts with; `chained`: linked to the last keyframe's.
  map::KeyFrameImu keyframe_imu(const Frame& f, bool chained) const;
  // optim::optimize_pose with the IMU's residual from prior_ (f.imu gets the velocity and biases).
  optim::PoseOnlyResult optimize_pose_inertial(Frame& f, const std::vector<optim::PosePointTerm>& points,
                                               const std::vector<optim::PoseLineTerm>& lines,
                                               const optim::PoseOnlyOptions& options);
  // A frame vision could not track, within max_inertial_s of the last it did: the IMU's pose.
  bool carry_by_imu(Frame& f);
  // ImuTrackingOptions::map_new_views: a keyframe at the IMU's pose for a view the map lacks.
  bool map_new_view_from_imu(Frame& f, TrackResult& result);
  // The map points and lines of the keyframes nearest f's pose (the IMU's prediction) that look
  // within 45 deg of its direction, at most local_map_covisibles of them.
  struct NearPrediction {
    std::vector<map::MapPoint*> points;
    std::vector<map::MapLine*> lines;
    std::size_t keyframes = 0;
  };
  NearPrediction landmarks_near_imu_prediction(const Frame& f) const;
  // Whether t is at most max_inertial_s after the last frame vision tracked.
  bool within_inertial_window(double t) const;
  // Each stretch of frames the IMU carried alone was predicted forward from the frame before it:
  // where vision placed the frame after it (or BA moved the keyframe of a new view), the IMU's
  // prediction of that frame was off, by an error that grew over the stretch. It is spread over
  // the stretch in proportion to the time since its start (position and rotation apart). A 1 s
  // black-out of a walking render: the carried frames were up to 22 mm off after global BA.
  void smooth_inertial_stretches();
  // After a gap the last frame's matches and the reference keyframe may be out of view: the map
  // points of the keyframes nearest the IMU's predicted pose, searched by projection from it.
  bool track_from_imu_prediction(Frame& f, TrackStageTimes& t);
  bool track_with_motion_model(Frame& f, TrackStageTimes& t);
  // Pose from PnP RANSAC on the frame's point matches, when it succeeds.
  std::optional<geometry::SE3> pnp_from_matches(const Frame& f) const;
  bool track_reference_keyframe(Frame& f, TrackStageTimes& t);
  bool track_local_map(Frame& f, TrackStageTimes& t, int& point_inliers, int& line_inliers);
  // Relocalization (see RelocalizationOptions); on success `f` holds the pose and matches and
  // the candidate keyframe becomes the reference. Defined in tracker_relocalization.cpp.
  bool relocalize(Frame& f, TrackStageTimes& t, long& keyframe_id);
  // Relocalization, then local map tracking and the keyframe decision; true when both succeed.
  // The frame then recovers (recovery_) until confirm_relocalization().
  bool relocalize_and_track(Frame& f, TrackResult& result);
  void confirm_relocalization(const Frame& f, TrackResult& result);
  // While lost: whether this frame should start a new map segment instead of waiting for
  // relocalization.
  bool should_start_new_segment(const Frame& f);
  // Relocalization is on: enabled and a keyframe database to query.
  bool relocalization_on() const { return database_ && options_.relocalization.enabled; }
  // Whether the frame has the stereo points to start a map (init_min_points).
  bool can_start_map(const Frame& f) const;
  // The keyframe decision and bookkeeping of a tracked frame.
  void finish_tracked_frame(Frame& f, TrackResult& result);
  // `covariance`: also the pose's (Frame::pose_covariance), for the final optimisation.
  int optimize_pose(Frame& f, TrackStageTimes& t, bool covariance = false);
  void update_local_map(Frame& f);
  map::KeyFrame* create_keyframe(Frame& f);
  // A map point (line) from the frame's stereo depth (3D endpoints), observed by `kf`.
  void create_stereo_point(Frame& f, map::KeyFrame* kf, std::size_t i);
  void create_stereo_line(Frame& f, map::KeyFrame* kf, std::size_t j);
  KeyframeInputs keyframe_inputs(const Frame& f, int point_inliers, int line_inliers) const;
  double close_depth(const Frame& f) const;
  // Where the constant-velocity model puts `f`, from the last frame and the time between them.
  geometry::SE3 predicted_pose(const Frame& f) const;
  // Compares the tracked pose of `f` with the prediction (call before the velocity is updated);
  // true for a suspect jump.
  bool check_motion(const Frame& f);
  // Without a velocity (the frame after a relocalization or a new map): whether `f` lies further
  // from the last tracked pose than a camera at relocalization.max_speed can have moved (a
  // suspect jump, recorded).
  bool beyond_reach(const Frame& f);
  // A recovering frame (tracked from an unconfirmed relocalization): whether it still matches
  // enough of the local map (kHolds), matches enough but with inliers in too few image cells
  // (kCellMiss, forgiven up to relocalization.max_cell_misses), or refutes the relocalization.
  enum class RecoveryCheck { kHolds, kCellMiss, kRefuted };
  RecoveryCheck check_recovery(const Frame& f, bool jumped) const;
  // How many of `points` are visible from the pose of `f`, how many map points `f` matched, and
  // whether those are at least relocalization.min_found_ratio of them: a true place explains a
  // good share of what the map shows there, a look-alike only what repeats.
  struct Explained {
    int matched = 0;
    int visible = 0;
    bool enough = false;
  };
  Explained explained(const Frame& f, const std::vector<map::MapPoint*>& points) const;

  map::Map& map_;
  TrackerOptions options_;
  std::function<void(map::KeyFrame*)> insert_keyframe_;
  std::function<bool()> mapping_idle_;
  KeyframePolicy policy_;

  TrackingState state_ = TrackingState::kNotInitialized;
  std::optional<Frame> last_;
  std::optional<geometry::SE3> velocity_;  // T_cur_last of the previous step
  double velocity_dt_ = 0;                  // seconds that step spanned
  map::KeyFrame* reference_ = nullptr;
  // The first frame after a stretch the IMU carried: its record, and the IMU's prediction of it
  // as a record with the stretch's reference (smooth_inertial_stretches).
  struct StretchEnd {
    std::size_t record = 0;
    FrameRecord predicted;
  };
  std::vector<StretchEnd> stretch_ends_;
  bool last_carried_ = false;  // the last frame was carried by the IMU alone
  map::KeyFrame* last_keyframe_ = nullptr;
  std::vector<map::KeyFrame*> local_keyframes_;
  std::vector<map::MapPoint*> local_points_;
  std::vector<map::MapLine*> local_lines_;
  core::PointerSet seen_points_, seen_lines_;  // update_local_map's deduplication
  std::vector<FrameRecord> records_;
  std::optional<std::size_t> last_tracked_record_;  // index into records_, the last trusted one
  // An unconfirmed relocalization: the frame that relocalized and the frames tracked from it so far.
  struct Recovery {
    long since_frame = 0;
    int frames = 0;
    geometry::SE3 T_cw;  // the relocalized pose
    bool after_gap = false;  // started by tracking across a gap, not by a relocalization
    bool trusted_before = false;  // trusted_since_recovery_ when it started
    int cell_misses = 0;  // recovering frames forgiven a miss (RelocalizationOptions::max_cell_misses)
    // Recovering frames checked that held: `frames` counts the relocalizing frame too.
    int held() const { return after_gap ? frames : frames - 1; }
  };
  // Whether the recovery has seen enough (RelocalizationOptions::confirm_*) with `f` tracked.
  bool recovery_confirmed(const Frame& f) const;
  std::optional<Recovery> recovery_;
  bool trusted_since_recovery_ = false;  // no recovery started since the last trusted frame
  // Whether `f`, just relocalized, continues the trusted trajectory (continuity_s).
  bool continues_trusted_motion(const Frame& f) const;
  std::vector<long> refuted_relocalizations_;
  long seen_big_changes_ = 0;  // map_.big_changes() when the last frame was tracked
  int lost_events_ = 0;
  int motion_wide_retries_ = 0;
  int keyframes_refused_queue_full_ = 0;
  std::vector<double> motion_deviation_m_, motion_deviation_deg_;
  std::vector<SuspectJump> suspect_jumps_;
  std::function<std::size_t()> mapping_queue_;
  const place::KeyframeDatabase* database_ = nullptr;
  std::optional<double> lost_since_;  // first textured frame that failed to relocalize
  std::vector<long> relocalized_frames_;
  std::vector<long> new_segment_frames_;

  const ImuData* imu_ = nullptr;
  geometry::SE3 T_imu_cam_;
  std::optional<ImuPrior> prior_;  // of the frame being tracked, on its normal path only
  inertial::ImuBias last_bias_;    // the latest estimate (seeds)
  std::optional<double> last_visual_t_;  // the last frame vision tracked
  // The IMU chain reaches the current frame: tracked without a loss since its last keyframe.
  bool imu_chain_live_ = false;
  // Keyframes with lower ids were loaded from a map file: their times are another run's clock,
  // so the IMU chain never links to them.
  long own_keyframes_from_ = 0;
  int imu_tracked_frames_ = 0;
  int inertial_frames_ = 0;
  int new_views_from_imu_ = 0;
};

}  // namespace plslam::tracking
