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
  // The keyframe the pose hangs on (-1: none) and the camera centre in its frame: the trail moves
  // with that keyframe when local BA, a loop correction or a global BA moves it.
  long anchor_keyframe = -1;
  Eigen::Vector3d centre_in_anchor = Eigen::Vector3d::Zero();
  long loops = 0, relocalizations = 0, frames = 0, tracked_frames = 0;
  double fps = 0;
  std::vector<long> local_keyframes, local_points;
  // The left image (shares the frame's pixels) and what tracking matched in it; the publisher
  // draws and encodes it (JPEG, half size) at every other update, off the tracking thread.
  cv::Mat left;
  std::vector<cv::Point2f> tracked_points;
  std::vector<std::pair<cv::Point2f, cv::Point2f>> tracked_lines;
};

// The live trajectory as the page draws it. Each tracked centre hangs on its anchor keyframe and
// is moved with that keyframe's pose in each snapshot; a centre whose keyframe is gone keeps its
// place. The page has the centres up to page_size(): only the new tail goes out, unless a centre
// it has moved by more than `resend_move_m` (a loop correction, a global BA; local BA's
// millimetres are not worth resending a long trail five times a second).
class LiveTrail {
 public:
  explicit LiveTrail(double resend_move_m = 0.01) : resend_move_m_(resend_move_m) {}
  void add(long keyframe, const Eigen::Vector3d& centre_in_keyframe, const Eigen::Vector3d& centre_world);
  // Moves every centre with its keyframe; true when the page must get the whole trail again.
  bool update(const map::MapSnapshot& map);
  // The page now has every centre (`whole`: resent; else: the tail after page_size() appended).
  void sent(bool whole);
  const std::vector<Eigen::Vector3d>& centres() const { return centres_; }
  std::size_t page_size() const { return page_.size(); }

 private:
  struct Anchor {
    long keyframe;
    Eigen::Vector3d in_keyframe;
  };
  double resend_move_m_;
  std::vector<Anchor> anchors_;
  std::vector<Eigen::Vector3d> centres_;  // world, as of the last update
  std::vector<Eigen::Vector3d> page_;     // world, as the page has them
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
  LiveTrail trail_;  // publisher thread only

  // Publisher thread state.
  std::shared_ptr<const Scene> last_;  // the state of the last revision
  map::MapSnapshot page_;              // what a page that applied every delta holds
  long image_updates_ = 0;
  long last_changes_ = -1;
  std::atomic<long> revision_{0};

  std::mutex stop_mutex_;
  std::condition_variable stop_cv_;
  bool stop_ = false;
  std::thread thread_;
};

// How far a keyframe or landmark must move from where the page has it to be sent again. Local BA
// moves thousands of points by a few millimetres every second; resent at 1 mm they were most of
// each delta. 5 mm is under a pixel of a room-sized map fitted to the page, and the final
// revision has every position exact.
inline constexpr double kPageMinMove = 5e-3;

// The change from `page` (what the page holds) to `after` as the page applies it: upserted and
// removed keyframes, points and lines (a keyframe or landmark counts as changed when it is more
// than `min_move_m` from where the page has it), the graph, counts, camera, local map, and of the
// trajectory the points after the first `trail_sent` ("trajectory_append"), or all of it
// ("trajectory", replacing the page's) when `trail_sent` is empty.
// `page_after`, when given, receives what the page holds once it applied the delta: `after`, but
// with what was not sent where the page has it, so that small moves add up until one is sent.
// `page_info`, when given, is the info the page got last: the local map is left out when it is
// the same (its ids, thousands of them, change with keyframes, not with every update), and the
// page keeps the one it has.
nlohmann::json scene_delta(const map::MapSnapshot& page, const map::MapSnapshot& after, const SceneInfo& info,
                           std::optional<std::size_t> trail_sent, long revision, double min_move_m = kPageMinMove,
                           map::MapSnapshot* page_after = nullptr, const SceneInfo* page_info = nullptr);

}  // namespace plslam::viz
