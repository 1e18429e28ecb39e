#pragma once
// Live stereo input. A camera delivers frames at its own rate whether or not SLAM keeps up, so
// capture must never wait for tracking: a capture thread takes every frame from the source as it
// arrives and puts it in a one-slot buffer that holds only the latest frame. A frame still in the
// slot when the next one arrives was not taken in time: it is dropped and counted. Tracking thus
// always gets the newest frame, and the device's own queue never fills (V4L2 would then hand out
// stale frames, or drop them where nobody counts).
#include <chrono>
#include <condition_variable>
#include <cstddef>
#include <exception>
#include <memory>
#include <mutex>
#include <optional>
#include <string>
#include <thread>

#include <opencv2/core.hpp>

#include "plslam/io/dataset.h"

namespace plslam::io {

struct CapturedFrame {
  cv::Mat left, right;  // 8-bit grey, rectified
  double timestamp = 0; // seconds, increasing
};

// Where live frames come from (a V4L2 camera, or a test's fake).
class FrameSource {
 public:
  virtual ~FrameSource() = default;
  // Blocks until the next frame; nullopt when the source has ended for good. May throw
  // InputError (a camera unplugged), which ends the capture and reaches the consumer.
  virtual std::optional<CapturedFrame> capture() = 0;
  // Names the source in messages and in StereoFrame::left_path (e.g. "/dev/video0").
  virtual std::string name() const = 0;
};

class LiveCapture {
 public:
  // Starts the capture thread at once.
  explicit LiveCapture(std::unique_ptr<FrameSource> source);
  ~LiveCapture();  // stop()
  LiveCapture(const LiveCapture&) = delete;
  LiveCapture& operator=(const LiveCapture&) = delete;

  // Takes the latest frame not taken yet, waiting at most `timeout` for one: nullopt when none
  // came in time or the source has ended (ended() tells). The frame's index counts every frame
  // captured, so the frames dropped before it leave a gap. A source's exception is rethrown here
  // once the frames before it are taken.
  std::optional<StereoFrame> next(std::chrono::milliseconds timeout);
  // True once the source has ended and its last frame was taken.
  bool ended() const;
  // Stops capturing and joins the thread (at the end of the source's current capture()).
  void stop();

  std::size_t captured() const;  // frames the source delivered
  std::size_t taken() const;     // frames next() returned
  std::size_t dropped() const;   // frames replaced in the slot before anyone took them
  const std::string& name() const { return name_; }

 private:
  void run();

  std::unique_ptr<FrameSource> source_;
  const std::string name_;
  mutable std::mutex mutex_;
  std::condition_variable cv_;
  std::optional<StereoFrame> slot_;
  std::size_t captured_ = 0, taken_ = 0, dropped_ = 0;
  bool source_ended_ = false;
  bool stop_ = false;
  std::exception_ptr error_;
  std::thread worker_;  // last member: started after everything above is initialised
};

}  // namespace plslam::io
