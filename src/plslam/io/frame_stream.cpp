#include "plslam/io/frame_stream.h"

#include <spdlog/spdlog.h>

#include "plslam/core/error.h"
#include "plslam/core/thread_priority.h"

namespace plslam::io {

FrameStream::FrameStream(const Dataset& dataset, std::size_t capacity, bool deliver_blank)
    : dataset_(dataset),
      capacity_(capacity == 0 ? 1 : capacity),
      deliver_blank_(deliver_blank),
      input_frames_(dataset.size()),
      worker_([this] {
        core::name_this_thread("plslam-loader");
        run();
      }) {}

FrameStream::~FrameStream() {
  {
    std::lock_guard lock(mutex_);
    stop_ = true;
  }
  cv_.notify_all();
  worker_.join();
}

void FrameStream::run() {
  try {
    for (std::size_t i = 0; i < dataset_.size(); ++i) {
      {
        std::unique_lock lock(mutex_);
        cv_.wait(lock, [this] { return stop_ || queue_.size() < capacity_; });
        if (stop_) break;
      }
      std::optional<StereoFrame> frame;
      std::string reason;
      try {
        frame = dataset_.load(i);
        if (!frame->problem.empty() && !(deliver_blank_ && frame->blank)) {
          reason = frame->problem;
          frame.reset();
          spdlog::warn("skipping frame {}: {}", i, reason);
        }
      } catch (const InputEnded& e) {
        // Frames i and later do not exist: the sequence ends here rather than skipping each.
        spdlog::warn("{}; the sequence ends at frame {} of {}", e.what(), i, dataset_.size());
        std::lock_guard lock(mutex_);
        input_frames_ = i;
        break;
      } catch (const InputError& e) {
        reason = e.what();
        spdlog::warn("skipping frame {}: {}", i, reason);
      }
      std::lock_guard lock(mutex_);
      if (frame) {
        queue_.push_back(std::move(*frame));
      } else {
        skipped_.push_back({i, dataset_.timestamps()[i], std::move(reason)});
      }
      cv_.notify_all();
    }
  } catch (...) {
    std::lock_guard lock(mutex_);
    error_ = std::current_exception();
  }
  std::lock_guard lock(mutex_);
  done_ = true;
  cv_.notify_all();
}

std::optional<StereoFrame> FrameStream::next() {
  std::unique_lock lock(mutex_);
  cv_.wait(lock, [this] { return !queue_.empty() || done_; });
  if (!queue_.empty()) {
    StereoFrame f = std::move(queue_.front());
    queue_.pop_front();
    cv_.notify_all();
    return f;
  }
  if (error_) std::rethrow_exception(error_);
  return std::nullopt;
}

std::size_t FrameStream::input_frames() const {
  std::lock_guard lock(mutex_);
  return input_frames_;
}

std::size_t FrameStream::skipped() const {
  std::lock_guard lock(mutex_);
  return skipped_.size();
}

std::vector<SkippedFrame> FrameStream::skipped_frames() const {
  std::lock_guard lock(mutex_);
  return skipped_;
}

std::size_t FrameStream::queued() const {
  std::lock_guard lock(mutex_);
  return queue_.size();
}

}  // namespace plslam::io
