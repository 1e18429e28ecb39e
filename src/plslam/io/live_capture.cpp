#include "plslam/io/live_capture.h"

#include "plslam/core/thread_priority.h"

namespace plslam::io {

LiveCapture::LiveCapture(std::unique_ptr<FrameSource> source)
    : source_(std::move(source)), name_(source_->name()), worker_([this] {
        core::name_this_thread("plslam-capture");
        run();
      }) {}

LiveCapture::~LiveCapture() { stop(); }

void LiveCapture::stop() {
  {
    std::lock_guard lock(mutex_);
    stop_ = true;
  }
  cv_.notify_all();
  if (worker_.joinable()) worker_.join();
}

void LiveCapture::run() {
  try {
    for (;;) {
      {
        std::lock_guard lock(mutex_);
        if (stop_) break;
      }
      // Outside the lock: the consumer must be able to take the slot while the source waits.
      auto frame = source_->capture();
      std::lock_guard lock(mutex_);
      if (!frame) break;
      StereoFrame f;
      f.index = captured_++;
      f.timestamp = frame->timestamp;
      f.left = std::move(frame->left);
      f.right = std::move(frame->right);
      f.left_path = f.right_path = name_;
      if (slot_) ++dropped_;
      slot_ = std::move(f);
      cv_.notify_all();
    }
  } catch (...) {
    std::lock_guard lock(mutex_);
    error_ = std::current_exception();
  }
  std::lock_guard lock(mutex_);
  source_ended_ = true;
  cv_.notify_all();
}

std::optional<StereoFrame> LiveCapture::next(std::chrono::milliseconds timeout) {
  std::unique_lock lock(mutex_);
  cv_.wait_for(lock, timeout, [this] { return slot_.has_value() || source_ended_; });
  if (slot_) {
    std::optional<StereoFrame> f = std::move(slot_);
    slot_.reset();
    ++taken_;
    return f;
  }
  if (source_ended_ && error_) {
    const auto e = error_;
    error_ = nullptr;  // reported once
    std::rethrow_exception(e);
  }
  return std::nullopt;
}

bool LiveCapture::ended() const {
  std::lock_guard lock(mutex_);
  return source_ended_ && !slot_;
}

std::size_t LiveCapture::captured() const {
  std::lock_guard lock(mutex_);
  return captured_;
}

std::size_t LiveCapture::taken() const {
  std::lock_guard lock(mutex_);
  return taken_;
}

std::size_t LiveCapture::dropped() const {
  std::lock_guard lock(mutex_);
  return dropped_;
}

}  // namespace plslam::io
