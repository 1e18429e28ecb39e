#pragma once
// The loop-closing thread (ORB-SLAM2's LoopClosing): local mapping hands it each keyframe it has
// processed; it detects a revisited place (loop_detector.h), verifies it in SE(3)
// (loop_verifier.h), confirms it by projecting the place's map points into the keyframe and
// refining the pose over their reprojection errors, and corrects the map (loop_correction.h)
// while local mapping is paused and tracking waits on the map's update lock.
#include <atomic>
#include <chrono>
#include <condition_variable>
#include <deque>
#include <memory>
#include <mutex>
#include <optional>
#include <thread>
#include <vector>

#include "plslam/loop/global_ba.h"
#include "plslam/loop/loop_correction.h"
#include "plslam/loop/loop_detector.h"
#include "plslam/loop/loop_verifier.h"
#include "plslam/mapping/local_mapper.h"
#include "plslam/place/keyframe_database.h"

namespace plslam::loop {

struct LoopClosingOptions {
  LoopDetectorOptions detector;
  LoopVerifierOptions verifier;
  LoopCorrectionOptions correction;
  // After the place's map points are projected into the keyframe and the pose refined over their
  // reprojection errors, this many must be inliers (ORB-SLAM2: 40).
  int min_projection_inliers = 40;
  double projection_radius = 10;  // pixels at the predicted level (ORB-SLAM2: 10)
  // Plausibility: odometry drifts by a few percent of the distance travelled at most, so a loop
  // that would move the keyframe by more than max_drift_ratio of the path from the recognised
  // place (plus min_drift_m), or turn it by more than max_drift_deg, is perceptual aliasing that
  // geometry could not tell apart (repeated textures at another place of a corridor).
  double max_drift_ratio = 0.05;
  double min_drift_m = 0.3;
  double max_drift_deg = 10;
  // No new loop within this many keyframes of the last one (ORB-SLAM2: 10).
  int keyframes_between_loops = 10;
  // Global BA after each loop, in its own thread (in the caller's with process_pending()).
  bool global_ba = true;
  // Also after a revisit that tracking found by relocalizing in the same map (a kidnapped camera,
  // or a loss): loop detection skips such a place, since relocalization already tied the new
  // keyframes to it, so without this the revisit's keyframes never meet the first pass's in one
  // optimisation. Needs global_ba.
  bool global_ba_after_relocalization = true;
  // ... and before it, a loop across the loss: the last keyframe tracking made before it, verified
  // against the revisit's first keyframe and its place like a detected loop (SE(3), projection,
  // plausibility over the path since the place). When the loss hid the moment a loop would have been
  // detected (a black-out as the camera comes back to the start), the relocalization ties the
  // revisit to the place, but only this ties the drifted end of the path to it.
  bool loop_across_relocalization = true;
  // Its first check asks less than a detected loop's (verifier): the relocalization already put the
  // camera at the place, and the keyframe before the loss sees it only at the edge of its view (16-17
  // BoW matches on the office loop, where the projection check then kept 122 inliers). The
  // projection check and the plausibility bound are those of any loop.
  LoopVerifierOptions across_verifier = [] {
    LoopVerifierOptions v;
    v.min_matches = 12;
    v.min_inliers = 10;
    return v;
  }();
  GlobalBaOptions global_ba_options;
  // At the end of a run, how long finish() waits for a running global BA before aborting it.
  double finish_wait_s = 120;
  // The deterministic pipeline: the global BA's snapshot is taken where it starts (in the caller,
  // at a point fixed by the frames), it optimises in its own thread, and its result enters the map
  // only when the caller says, with merge_deferred_global_ba() at a frame fixed in advance. A
  // later loop or revisit drops a result not merged yet, as it aborts a running one.
  bool defer_global_ba_merge = false;
  // ... and that frame: the first whose timestamp is this many seconds after the frame whose
  // keyframe started it (tracking waits there if the optimisation is not done). Long enough for
  // the optimisation to finish beside tracking and mapping on 2 cores, so no frame waits.
  double global_ba_merge_after_s = 3.0;
  // The deterministic pipeline's loop closing: process_pending() (beside tracking) detects and
  // verifies only, and never writes the map; the caller then, at frames fixed in advance, begins a
  // verified loop's correction (the query's neighbourhood onto the place, fusion), leaves its
  // essential graph to a thread, and finishes it (the rest of the map; the global BA starts),
  // and starts a global BA asked for by a relocalized revisit.
  bool defer_loop_correction = false;
  // ... the correction's end: this many frames after its beginning (tracking waits there if the
  // essential graph is not solved yet).
  int correction_merge_after_frames = 2;
  // Throws std::invalid_argument naming the bad field.
  void validate() const;
};

struct LoopRecord {
  long frame = 0;             // the query keyframe's frame
  long keyframe = 0;          // its id
  long matched_keyframe = 0;  // the recognised place's keyframe
  long matched_frame = 0;
  int inliers = 0;            // after the projection search and refinement
  int fused_points = 0;
  int fused_lines = 0;
  double correction_ms = 0;
};

struct LoopClosingStats {
  std::vector<LoopRecord> loops;
  int detections = 0;     // candidates the detector passed on
  int rejected = 0;       // of them, failed verification, the projection or the plausibility check
  int implausible = 0;    // of the rejected, those that passed the geometry but not plausibility
  std::vector<double> global_ba_ms;  // per merged global BA: snapshot, optimisation and merge
  int global_ba_runs = 0;            // merged
  int global_ba_aborted = 0;         // made obsolete by a newer loop, or cut at finish()
  int global_ba_after_relocalization = 0;  // started for a relocalized revisit (no loop)
  int global_ba_inertial_refinements = 0;  // started to refine the IMU's initialisation (no loop)
  int loops_across_relocalization = 0;     // of the loops, those closed across a relocalization
};

class LoopCloser {
 public:
  LoopCloser(map::Map& map, const place::KeyframeDatabase& database, mapping::LocalMapper& mapper,
             LoopClosingOptions options);
  ~LoopCloser();
  LoopCloser(const LoopCloser&) = delete;
  LoopCloser& operator=(const LoopCloser&) = delete;

  void start();
  // Processes what is queued, then stops and joins.
  void stop();
  void insert(map::KeyFrame* kf);
  // Tracking relocalized in the same map after a loss, and keyframe `keyframe_id` is the first it
  // made since: once that keyframe (or a later one, if it was culled) has been mapped and passed
  // through loop detection without a loop, a global BA runs (global_ba_after_relocalization).
  // `before_loss_keyframe_id`: the reference keyframe of the last trusted frame before the loss, for
  // loop_across_relocalization (-1: none).
  void global_ba_after_keyframe(long keyframe_id, long before_loss_keyframe_id = -1);
  // A visual-inertial map (use_imu) some seconds after the IMU's initialisation: once keyframe
  // `keyframe_id` (or a later one) has passed through loop detection, a global BA with the IMU
  // factors runs, unless that keyframe closed a loop (whose global BA is the same).
  void refine_inertial_after_keyframe(long keyframe_id);
  // Processes every queued keyframe in the calling thread (sequential mode and tests).
  void process_pending();
  void wait_idle();
  // wait_idle(), then waits up to options.finish_wait_s for a running global BA (aborting it after
  // that, with a warning); returns false if it had to abort.
  bool finish();
  // defer_global_ba_merge: how many global BAs have started (the caller notes a new one to fix
  // the frame of its merge), and the merge itself: waits for the optimisation, then writes it into
  // the map (local mapping must be at rest). True if a result was merged; false if none was pending,
  // or it was dropped or unusable. Call from the thread that calls process_pending().
  long global_ba_starts() const { return gba_starts_; }
  bool merge_deferred_global_ba();
  // defer_loop_correction, called where no other thread reads or writes the map, in this order:
  // keyframes waiting for process_pending(): their covisibility after a correction or a global BA
  // changed the map (which process_pending() would otherwise update, beside tracking's reads);
  // then the deferred steps, and whether one is waiting.
  std::size_t queued() const;
  void refresh_queued_connections();
  bool global_ba_requested() const { return gba_requested_; }
  void start_requested_global_ba();  // aborts a running one
  bool loop_pending() const { return pending_loop_.has_value(); }
  void begin_deferred_correction();
  bool correction_open() const { return open_correction_ != nullptr; }
  void finish_deferred_correction();  // waits for the essential graph
  // Holds loop closing only if idle: nothing queued or in progress, no global BA running; true if
  // it did (resume() after). For Map::reclaim(), which needs every thread at rest.
  bool try_pause();
  void resume();
  // The map is visual-inertial from now on: global BA keeps the IMU chain's factors. Call while
  // paused with try_pause() (no global BA running).
  void use_imu(const geometry::SE3& T_imu_cam) { options_.global_ba_options.T_imu_cam = T_imu_cam; }
  LoopClosingStats stats() const;

 private:
  void run();
  void process(map::KeyFrame* kf);
  // Detection, verification and correction; true if a loop was closed.
  bool close_loop(map::KeyFrame* kf);
  // Global BA in its own thread (in the caller's in sequential mode).
  void start_global_ba();
  // The loop across a relocalization (loop_across_relocalization): `before` is the query, the
  // revisit's keyframe `kf` the place. True if a loop was closed.
  bool close_loop_across_relocalization(map::KeyFrame* kf, long before_id);
  // Correction, records and global BA of a confirmed loop; `newest` is the latest keyframe involved
  // (defer_loop_correction: the loop waits for begin_deferred_correction()).
  void correct(const LoopConstraint& loop, map::KeyFrame* newest);
  // The log line and the statistics of a corrected loop, and its global BA.
  void corrected(const LoopConstraint& loop, const LoopCorrectionResult& result, double ms);
  // The deferred steps of defer_loop_correction, at the end of a run.
  void settle_deferred_steps();
  // Verification and the projection check; the constraint to correct with, if the place holds.
  // `path_from`: the keyframe id the drift is counted from (-1: the candidate's).
  std::optional<LoopConstraint> confirm(map::KeyFrame* kf, const LoopDetection& d, const LoopVerifierOptions& verifier,
                                       long path_from = -1);
  // Whether moving the query to T_qw_corrected is within what odometry drift can explain over the
  // path from keyframe `path_from` to the query.
  bool plausible(map::KeyFrame* query, map::KeyFrame* candidate, const geometry::SE3& T_qw_corrected, long path_from);
  // Snapshot, optimise, merge (unless aborted).
  void global_ba();
  // defer_global_ba_merge: the snapshot here, the optimisation in gba_thread_.
  void start_deferred_global_ba();
  // Joins the global BA thread, cutting it short; a deferred result not merged yet is dropped.
  void abort_global_ba();
  // Requests the global BA refine_inertial_after_keyframe() asked for, once `kf` reaches its id.
  void serve_inertial_refinement(const map::KeyFrame& kf, bool loop_closed);
  // Writes a global BA's result into the map (unless it was aborted or is unusable, which is
  // counted) and records it; `t0`: when its snapshot was taken. True if merged.
  bool merge_into_map(const GlobalBaSnapshot& snapshot, const optim::BaResult& result,
                      std::chrono::steady_clock::time_point t0);

  map::Map& map_;
  const place::KeyframeDatabase& database_;
  mapping::LocalMapper& mapper_;
  LoopClosingOptions options_;
  LoopDetector detector_;
  long last_loop_keyframe_ = -1;
  std::atomic<long> revisit_keyframe_{-1};  // global_ba_after_keyframe()'s id, until served
  std::atomic<long> revisit_from_{-1};      // ... and the keyframe before the loss
  std::atomic<long> refine_keyframe_{-1};   // refine_inertial_after_keyframe()'s id, until served

  mutable std::mutex queue_mutex_;
  std::condition_variable cv_;
  std::deque<map::KeyFrame*> queue_;
  bool busy_ = false;
  bool stop_requested_ = false;
  int pauses_ = 0;
  std::thread thread_;

  std::thread gba_thread_;
  std::atomic<bool> gba_abort_{false};
  std::mutex gba_mutex_;
  std::condition_variable gba_cv_;
  bool gba_running_ = false;  // running, or (deferred) computed and not merged yet
  bool gba_computed_ = false;  // deferred: the optimisation has finished
  long gba_starts_ = 0;
  struct Deferred {
    GlobalBaSnapshot snapshot;
    optim::BaResult result;
    std::chrono::steady_clock::time_point t0;
  };
  std::unique_ptr<Deferred> deferred_;  // written by gba_thread_ until it is joined

  // defer_loop_correction: written by process_pending(), read by the caller's deferred steps.
  bool gba_requested_ = false;
  std::optional<LoopConstraint> pending_loop_;  // verified, its correction not begun
  struct OpenCorrection {
    LoopConstraint loop;
    LoopCorrectionPlan plan;
    EssentialGraphResult graph;  // written by graph_thread_ until it is joined
    double begin_ms = 0;
    double graph_ms = 0;
  };
  std::unique_ptr<OpenCorrection> open_correction_;
  std::thread graph_thread_;

  mutable std::mutex stats_mutex_;
  LoopClosingStats stats_;
};

}  // namespace plslam::loop
