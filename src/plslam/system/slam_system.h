#pragma once
// The SLAM system: frame extraction, the tracker, and the local mapping thread over one map.
// The caller's thread is the tracking thread; local mapping runs concurrently (or, with
// `sequential`, in the tracking thread after each keyframe, for reproducible runs).
#include <cstdint>
#include <memory>
#include <optional>

#include "plslam/core/types.h"
#include "plslam/io/dataset.h"
#include "plslam/map/map.h"
#include "plslam/mapping/local_mapper.h"
#include "plslam/tracking/frame_extractor.h"
#include "plslam/tracking/tracker.h"

namespace plslam::system {

struct SystemOptions {
  tracking::FrameExtractorOptions extractor;
  tracking::TrackerOptions tracker;
  mapping::LocalMapperOptions mapper;
  bool sequential = false;
  // Seed of every random choice (config `system.seed`, recorded in stats.json). Today the
  // pipeline makes none: tracking, mapping and BA are deterministic. The PnP RANSAC of
  // relocalization (geometry::PnpOptions::seed) takes it.
  std::uint32_t seed = 1;

  static SystemOptions euroc();
  static SystemOptions kitti();
  // Switches lines off everywhere (--no-lines).
  void disable_lines();
};

struct FrameResult {
  long frame_id = 0;      // the frame's index in the input
  double timestamp = 0;   // seconds
  tracking::TrackResult track;
  tracking::FrameTimings extraction;
  double tracking_ms = 0;  // images in to pose out
};

class System {
 public:
  System(const StereoCalibration& calib, SystemOptions options);
  ~System();
  System(const System&) = delete;
  System& operator=(const System&) = delete;

  FrameResult process(const io::StereoFrame& frame);
  // Lets local mapping finish its queue and stops it. Outputs are final after this.
  void finish();

  // The tracked frames only (never a prediction made while lost or before initialisation),
  // T_world_leftcam with world = the first keyframe's camera.
  Trajectory tracked_trajectory() const;
  // The id of the first frame that started a map; nullopt while none has.
  std::optional<long> initialized_at() const;
  Trajectory keyframe_trajectory() const;
  const map::Map& map() const { return map_; }
  const SystemOptions& options() const { return options_; }
  const tracking::Tracker& tracker() const { return *tracker_; }
  mapping::LocalMapperStats mapper_stats() const { return mapper_->stats(); }

 private:
  SystemOptions options_;
  map::Map map_;
  tracking::FrameExtractor extractor_;
  std::unique_ptr<mapping::LocalMapper> mapper_;
  std::unique_ptr<tracking::Tracker> tracker_;
  bool finished_ = false;
};

}  // namespace plslam::system
