#pragma once
// `plslam run --viewer`: the map as it grows, served to browsers while the run goes on.
//
// Tracking hands over a few values per frame (on_frame: a mutex and a copy of the local map's
// ids). A publisher thread of its own, at `rate_hz`, takes a snapshot of the map (map::
// take_snapshot), compares it with the last one and publishes what changed as a delta; the full
// document is only serialised when a browser asks for it (one that connects, or one too far
// behind), from the immutable state of that revision. Tracking never waits for a browser, and the
// server never touches the live map.
#include <chrono>
#include <condition_variable>
#include <memory>
#include <mutex>
#include <optional>
#include <string>
#include <thread>
#include <atomic>
#include <vector>

#include <nlohmann/json.hpp>
#include <opencv2/core.hpp>

#include "plslam/map/map.h"
#include "plslam/viz/scene_document.h"
#include "plslam/viz/viewer_server.h"

namespace plslam::viz {

// What the page's panel shows of the current frame.
struct LiveFrame {
  long frame = 0;
  std::string state;  // tracking state
  bool tracked = false;
  geometry::SE3 T_wc;
  long loops = 0, relocalizations = 0, frames = 0, tracked_frames = 0;
  double fps = 0;
  std::vector<long> local_keyframes, local_points;
  // The left image (shares the frame's pixels) and what tracking matched in it; the publisher
  // draws and encodes it (JPEG, half size) at every other update, off the tracking thread.
  cv::Mat left;
  std::vector<cv::Point2f> tracked_points;
  std::vector<std::pair<cv::Point2f, cv::Point2f>> tracked_lines;
};

struct LiveViewerOptions {
  ViewerServerOptions server;
  double rate_hz = 5;  // publishing rate; the page polls at about twice this
  void validate() const;
};

class LiveViewer {
 public:
  // Binds the server (InputError when the port is in use) and starts publishing. `base` holds the
  // fixed part of the document (name, camera model). The map must outlive the viewer.
  LiveViewer(LiveViewerOptions options, const map::Map& map, SceneInfo base);
  ~LiveViewer();
  LiveViewer(const LiveViewer&) = delete;
  LiveViewer& operator=(const LiveViewer&) = delete;

  std::string url() const { return server_.url(); }

  // Tracking thread, after each frame. Cheap: copies the values under a mutex.
  void on_frame(LiveFrame frame);

  // The run is over: stops the publisher and publishes `final_scene` (the run's outputs as
  // `plslam view` reads them) as the last, final revision.
  void finish(const Scene& final_scene);

  // Revisions published so far (for tests and the log).
  long revision() const;

 private:
  void publish_loop();
  void publish_once();

  const LiveViewerOptions options_;
  const map::Map& map_;
  SceneInfo base_;
  ViewerServer server_;

  std::mutex frame_mutex_;  // guards frame_, new_frame_
  std::optional<LiveFrame> frame_;
  bool new_frame_ = false;
  std::vector<Eigen::Vector3d> trail_;  // tracked camera centres, publisher thread only

  // Publisher thread state.
  std::shared_ptr<const Scene> last_;  // the state of the last revision
  std::size_t trail_sent_ = 0;
  long image_updates_ = 0;
  long last_changes_ = -1;
  std::atomic<long> revision_{0};

  std::mutex stop_mutex_;
  std::condition_variable stop_cv_;
  bool stop_ = false;
  std::thread thread_;
};

// The change from `before` to `after` as the page applies it: upserted and removed keyframes,
// points and lines (a landmark counts as changed when it moved by more than `min_move_m`), the
// graph, counts, camera, local map and the trajectory points after the first `trail_sent`.
nlohmann::json scene_delta(const map::MapSnapshot& before, const map::MapSnapshot& after, const SceneInfo& info,
                           std::size_t trail_sent, long revision, double min_move_m = 1e-3);

}  // namespace plslam::viz
