#pragma once
// Streams a dataset's frames in order while a background thread decodes (and rectifies) the next
// ones into a bounded queue: decoding overlaps processing, and memory stays flat however long
// the sequence is.
#include <condition_variable>
#include <cstddef>
#include <deque>
#include <exception>
#include <mutex>
#include <optional>
#include <string>
#include <thread>
#include <vector>

#include "plslam/io/dataset.h"

namespace plslam::io {

// A frame left out because its images could not be read; `index` is its place in the dataset
// (within the selected range), so the frames after it keep theirs.
struct SkippedFrame {
  std::size_t index = 0;
  double timestamp = 0;
  std::string reason;
};

class FrameStream {
 public:
  // deliver_blank: a frame whose images are blank (StereoFrame::blank) comes out of next() with its
  // problem set instead of being skipped; its taker decides (plslam run: the IMU carries it, or
  // it is skipped there).
  explicit FrameStream(const Dataset& dataset, std::size_t capacity = 4, bool deliver_blank = false);
  ~FrameStream();
  FrameStream(const FrameStream&) = delete;
  FrameStream& operator=(const FrameStream&) = delete;

  // The next frame, or nullopt at the end. A frame whose images cannot be decoded is reported
  // once (error log naming the file) and skipped; other failures are rethrown here.
  std::optional<StereoFrame> next();

  // The frames the input really holds: the dataset's size, or fewer when it ended early (a video
  // shorter than its header said; InputEnded). Final once next() has returned nullopt.
  std::size_t input_frames() const;

  std::size_t skipped() const;
  // Every frame skipped so far, in order, with the reason.
  std::vector<SkippedFrame> skipped_frames() const;
  std::size_t capacity() const { return capacity_; }
  // Frames decoded but not yet taken (never more than capacity()).
  std::size_t queued() const;

 private:
  void run();

  const Dataset& dataset_;
  const std::size_t capacity_;
  const bool deliver_blank_;
  mutable std::mutex mutex_;
  std::condition_variable cv_;
  std::deque<StereoFrame> queue_;
  std::vector<SkippedFrame> skipped_;
  std::size_t input_frames_;
  bool done_ = false;
  bool stop_ = false;
  std::exception_ptr error_;
  std::thread worker_;  // last member: started after everything above is initialised
};

}  // namespace plslam::io
