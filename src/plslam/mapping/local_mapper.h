#pragma once
// The local mapping thread (ORB-SLAM2's LocalMapping, with lines): takes new keyframes from
// tracking, adds their observations and covisibility edges, then runs the stages, each in a unit
// of its own: culling of recent landmarks (landmark_culling), triangulation of new points and lines
// with neighbouring keyframes (landmark_triangulation), fusion of duplicates (landmark_fusion),
// local BA (local_ba_window) and culling of redundant keyframes (keyframe_culling). This class
// owns the thread, the queue, pause/resume and the statistics.
#include <atomic>
#include <condition_variable>
#include <deque>
#include <functional>
#include <mutex>
#include <optional>
#include <thread>
#include <vector>

#include "plslam/map/map.h"
#include "plslam/mapping/keyframe_culling.h"
#include "plslam/mapping/landmark_culling.h"
#include "plslam/mapping/landmark_fusion.h"
#include "plslam/mapping/landmark_triangulation.h"
#include "plslam/mapping/local_ba_window.h"

namespace plslam::place {
class KeyframeDatabase;
}  // namespace plslam::place

namespace plslam::mapping {

struct LocalMapperOptions {
  bool local_ba = true;
  LocalBaOptions ba;
  TriangulationOptions triangulation;
  FusionOptions fusion;
  RecentLandmarkOptions recent;
  KeyframeCullingOptions keyframe_culling;
  // Shared with tracking and loop closing (the system sets them from TrackerOptions and
  // --no-lines); they reach the units' options from here, overriding the units' own copies.
  double line_information = 0.5;
  double far_stereo_baselines = 0;  // as TrackerOptions
  bool lines = true;
  // A keyframe queued while local BA runs cuts that BA short after its current iteration (what
  // ORB-SLAM2's tracking does): the partial result is written back, and mapping turns to the new
  // keyframe sooner. Only with the mapping thread; process_pending() never aborts. Off: measured
  // neutral (4 concurrent runs each, on/off, ATE median: rendered office loop 0.0083/0.0085 m,
  // KITTI 06 0.0276/0.0314, KITTI 01 0.566/0.539, all within the runs' spread), so the map keeps
  // the full BAs.
  bool abort_ba_on_new_keyframe = false;
  // Deterministic mode (System): a keyframe's local BA optimises beside the tracking of the next
  // frames, and its result enters the map before the frame this many frames after the keyframe's
  // is tracked, or earlier, before the next keyframe is mapped. 1: before the very next frame
  // (the map then evolves exactly as in sequential mode).
  int ba_merge_after_frames = 2;
  // ... and not before the frame whose input time is this many ms per 1000 observations of the BA's
  // window after the keyframe's: the solver's time grows with them (on the machine this was set
  // on, about 2.2 ms per 1000 alone, more beside tracking), and a window after a loop has twice
  // the usual. 0: by frames only.
  double ba_merge_ms_per_1000_observations = 3.0;
  // Keyframes of the IMU chain that local BA optimises with their IMU factors once use_imu() was
  // called (LocalBaOptions::imu_window; ORB-SLAM3: 10).
  int imu_window = 10;
};

struct LocalMapperStats {
  std::vector<double> local_ba_ms;
  std::vector<double> keyframe_ms;
  std::vector<double> triangulation_ms;  // per keyframe
  std::vector<double> fusion_ms;         // per keyframe that ran it
  int culled_keyframes = 0;
  int aborted_local_ba = 0;              // cut short by abort_ba(), pause() or a new keyframe
  // Keyframes whose local BA never started: more keyframes were waiting (fusion was skipped too),
  // or an abort (a pause for loop closing, a newer keyframe) came first.
  int skipped_local_ba = 0;
  // Deterministic mode: keyframes mapped in one go with a later one (they waited while a loop
  // correction was open), whose local BA is that later keyframe's, with them free in its window.
  int covered_local_ba = 0;
  // The most keyframes ever waiting in the queue (the one being processed not counted), each
  // insert() included: 1 when mapping always kept up. A queue that grows means mapping cannot
  // keep up, and the keyframes waiting skip fusion and local BA (process()).
  int max_queue = 0;
  std::vector<double> pause_wait_ms;     // per pause(): the wait for the keyframe in progress
  int triangulated_points = 0;
  int fused_points = 0;
};

class LocalMapper {
 public:
  LocalMapper(map::Map& map, LocalMapperOptions options);
  ~LocalMapper();
  LocalMapper(const LocalMapper&) = delete;
  LocalMapper& operator=(const LocalMapper&) = delete;

  // Starts the background thread. Without it, process_pending() runs the work in the caller.
  void start();
  // Processes what is queued, then stops and joins the thread.
  void stop();

  void insert(map::KeyFrame* kf);
  // Place recognition: each processed keyframe is described and added, each culled one forgotten.
  // Not owned; set before start().
  void set_keyframe_database(place::KeyframeDatabase* database) { database_ = database; }
  // Receives each keyframe once it is processed (loop closing's queue). Set before start().
  void set_keyframe_sink(std::function<void(map::KeyFrame*)> sink) { sink_ = std::move(sink); }
  // Loop closing: pause() aborts the local BA in progress (abort_ba()), returns once the keyframe
  // in progress is done, and no other starts until every pause() has had its resume() (loop
  // correction and the global BA merge may overlap). Keyframes keep queueing meanwhile. No effect
  // on process_pending().
  void pause();
  void resume();
  // Cuts the local BA in progress short after its current iteration; its partial result, which
  // every accepted iteration improved, is still written back. No effect when no BA runs; the flag
  // is cleared when the next keyframe starts.
  void abort_ba();
  bool idle() const;
  // Pauses only if idle (nothing queued, nothing in progress); true if it did (resume() after).
  bool try_pause();
  // Forgets the culled landmarks it keeps between keyframes (before Map::reclaim()); call while
  // paused with try_pause(), or from the thread that calls process_pending().
  void drop_bad_landmarks() { recent_.drop_bad(); }
  // The map is visual-inertial from now on (its keyframes get IMU states): local BA takes the IMU
  // chain's factors (LocalMapperOptions::imu_window). Call as drop_bad_landmarks().
  void use_imu(const geometry::SE3& T_imu_cam) {
    options_.ba.imu_window = options_.imu_window;
    options_.ba.T_imu_cam = T_imu_cam;
  }
  std::size_t queued() const;
  // Processes every queued keyframe in the calling thread (deterministic mode and tests).
  void process_pending();
  // Blocks until the queue is empty and the current keyframe is done.
  void wait_idle();

  // The deterministic mode's pipeline, in three steps that the system calls at frames it fixes.
  // process_pending_deferring_ba() processes the queued keyframes like process_pending(), except
  // that the last one's local BA is only prepared: its window is built (the map is read here), and
  // it covers the keyframes before it, which are fused and culled as usual but get no BA of their
  // own (they are free in its window: stats covered_local_ba, not skipped_local_ba).
  // optimise_deferred_ba() runs the solver, which reads only the window, so it may run in another
  // thread beside tracking, which then reads a map that nothing writes. finish_deferred() (a no-op
  // when nothing is deferred) optimises if that has not run, writes the result back, culls
  // redundant keyframes and hands the keyframe to loop closing. The next
  // keyframe's processing finishes a deferred one first; so does process_pending().
  void process_pending_deferring_ba();
  void optimise_deferred_ba();
  void finish_deferred();
  // Point and line observations in the deferred BA's window (0: none). From the thread that made it.
  std::size_t deferred_ba_observations() const;

  LocalMapperStats stats() const;

 private:
  void run();
  // Pops the front keyframe (lock held), processes it with the lock released, marks idle again.
  void process_front(std::unique_lock<std::mutex>& lock, bool defer = false, bool in_caller = false);
  // With `defer`, stops before the local BA's solver (process_pending_deferring_ba()). `in_caller`:
  // not the mapping thread (process_pending*), where keyframes waiting together share a BA.
  void process(map::KeyFrame* kf, bool more_waiting, bool defer, bool in_caller);
  // Adds the keyframe's observations of the landmarks tracking associated, and its covisibility
  // edges; the landmarks it made itself go on probation.
  void process_new_keyframe(map::KeyFrame* kf);
  void triangulate(map::KeyFrame* kf);
  void fuse(map::KeyFrame* kf);
  void cull_keyframes(map::KeyFrame* kf);

  map::Map& map_;
  LocalMapperOptions options_;
  place::KeyframeDatabase* database_ = nullptr;
  std::function<void(map::KeyFrame*)> sink_;

  mutable std::mutex queue_mutex_;
  std::condition_variable cv_;
  std::deque<map::KeyFrame*> queue_;
  bool busy_ = false;
  std::atomic<bool> abort_ba_{false};  // read by the BA between iterations
  bool stop_requested_ = false;
  int pauses_ = 0;
  std::thread thread_;

  // Touched only by the mapping thread (or the caller of process_pending()).
  RecentLandmarks recent_;
  // Deterministic mode: keyframes processed with more waiting, free in the next local BA's window.
  std::vector<map::KeyFrame*> covered_;
  // A processed keyframe whose last steps wait: its local BA (window empty: none due), its
  // keyframe culling and its hand-over to loop closing.
  struct Deferred {
    map::KeyFrame* kf = nullptr;
    bool more_waiting = false;
    std::optional<MapBaProblem> window;
    optim::BaResult result;
    bool optimised = false;
    double processing_ms = 0;  // before the solver, then with it
    double ba_ms = 0;          // the window's and the solver's
  };
  std::optional<Deferred> deferred_;
  bool deferred_open_ = false;  // deferred_ holds a keyframe; guarded by queue_mutex_ (try_pause)

  mutable std::mutex stats_mutex_;
  LocalMapperStats stats_;
};

}  // namespace plslam::mapping
