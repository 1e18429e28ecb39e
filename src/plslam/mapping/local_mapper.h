#pragma once
// The local mapping thread (ORB-SLAM2's LocalMapping, with lines): takes new keyframes from
// tracking, adds their observations and covisibility edges, culls recent map points and lines
// that tracking fails to find, triangulates new points with neighbouring keyframes, fuses
// duplicates, runs local BA over points and lines, and culls redundant keyframes.
#include <atomic>
#include <condition_variable>
#include <deque>
#include <functional>
#include <list>
#include <mutex>
#include <thread>
#include <vector>

#include "plslam/map/map.h"
#include "plslam/optim/bundle_adjustment.h"

namespace plslam::place {
class KeyframeDatabase;
}  // namespace plslam::place

namespace plslam::mapping {

struct LocalMapperOptions {
  bool local_ba = true;
  int ba_iterations = 5;         // first pass (ORB-SLAM2: 5 + 10 without outliers)
  int ba_second_iterations = 10;
  double line_information = 0.5;
  double far_stereo_baselines = 0;  // as TrackerOptions (set by the system from it)
  double culling_redundancy = 0.9;  // a keyframe is redundant when this share of its points is seen by 3 others
  int triangulation_neighbors = 10;
  bool lines = true;
};

struct LocalMapperStats {
  std::vector<double> local_ba_ms;
  std::vector<double> keyframe_ms;
  std::vector<double> triangulation_ms;  // per keyframe
  std::vector<double> fusion_ms;         // per keyframe that ran it
  int culled_keyframes = 0;
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
  // Loop closing: pause() returns once the keyframe in progress is done, and no other starts until
  // every pause() has had its resume() (loop correction and the global BA merge may overlap).
  // Keyframes keep queueing meanwhile. No effect on process_pending().
  void pause();
  void resume();
  bool idle() const;
  std::size_t queued() const;
  // Processes every queued keyframe in the calling thread (deterministic mode and tests).
  void process_pending();
  // Blocks until the queue is empty and the current keyframe is done.
  void wait_idle();

  LocalMapperStats stats() const;

 private:
  void run();
  // Pops the front keyframe (lock held), processes it with the lock released, marks idle again.
  void process_front(std::unique_lock<std::mutex>& lock);
  void process(map::KeyFrame* kf, bool more_waiting);
  void process_new_keyframe(map::KeyFrame* kf);
  void cull_recent(map::KeyFrame* kf);
  void triangulate(map::KeyFrame* kf);
  void fuse(map::KeyFrame* kf);
  void local_bundle_adjustment(map::KeyFrame* kf);
  void cull_keyframes(map::KeyFrame* kf);

  map::Map& map_;
  LocalMapperOptions options_;
  place::KeyframeDatabase* database_ = nullptr;
  std::function<void(map::KeyFrame*)> sink_;

  mutable std::mutex queue_mutex_;
  std::condition_variable cv_;
  std::deque<map::KeyFrame*> queue_;
  bool busy_ = false;
  bool stop_requested_ = false;
  int pauses_ = 0;
  std::thread thread_;

  // Touched only by the mapping thread (or the caller of process_pending()).
  std::list<std::pair<map::MapPoint*, long>> recent_points_;  // point, keyframe id that made it
  std::list<std::pair<map::MapLine*, long>> recent_lines_;

  mutable std::mutex stats_mutex_;
  LocalMapperStats stats_;
};

}  // namespace plslam::mapping
