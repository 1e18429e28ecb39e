// Live capture keeps only the newest frame: a slow consumer makes the capture thread drop frames
// and count them, never wait. Driven by a fake source, as fast as it goes.
#include <atomic>
#include <chrono>
#include <thread>

#include <gtest/gtest.h>

#include "plslam/core/error.h"
#include "plslam/io/live_capture.h"

namespace plslam::io {
namespace live_capture_test {  // named: the unity build joins the test files

using namespace std::chrono_literals;

// Delivers `frames` frames (then ends), each after `period`, stamping frame i's pixels with i
// so a test can tell which frame it got; throws after the last one when `fail` is set. With a
// `taken` counter, each frame (and the end) waits until the consumer has counted every frame
// before it: a consumer that always keeps up, whatever the machine's load (a real-time "fast
// consumer" test failed under ThreadSanitizer when the consumer thread slept past one period).
class FakeSource final : public FrameSource {
 public:
  FakeSource(std::size_t frames, std::chrono::microseconds period, bool fail = false,
             const std::atomic<std::size_t>* taken = nullptr)
      : frames_(frames), period_(period), fail_(fail), taken_(taken) {}

  std::optional<CapturedFrame> capture() override {
    // Bounded, so a broken consumer fails the test instead of hanging it.
    for (int i = 0; taken_ && *taken_ < delivered_ && i < 100000; ++i) std::this_thread::sleep_for(100us);
    if (delivered_ == frames_) {
      if (fail_) throw InputError("/dev/fake", "no frame: the camera stopped delivering (unplugged?)");
      return std::nullopt;
    }
    std::this_thread::sleep_for(period_);
    CapturedFrame f;
    f.left = cv::Mat(4, 6, CV_8UC1, cv::Scalar(static_cast<double>(delivered_ % 256)));
    f.right = f.left.clone();
    f.timestamp = 0.001 * static_cast<double>(delivered_);
    ++delivered_;
    return f;
  }
  std::string name() const override { return "/dev/fake"; }

  std::atomic<std::size_t>& delivered() { return delivered_; }

 private:
  const std::size_t frames_;
  const std::chrono::microseconds period_;
  const bool fail_;
  const std::atomic<std::size_t>* taken_;
  std::atomic<std::size_t> delivered_{0};
};

// Frames a consumer took until the source ended (counted in `taken` when given).
std::vector<StereoFrame> take_all(LiveCapture& capture, std::chrono::milliseconds work,
                                  std::atomic<std::size_t>* taken = nullptr) {
  std::vector<StereoFrame> got;
  while (!capture.ended()) {
    auto f = capture.next(1000ms);
    if (!f) continue;
    got.push_back(std::move(*f));
    if (taken) ++*taken;
    std::this_thread::sleep_for(work);  // "tracking"
  }
  return got;
}

TEST(LiveCapture, AFastConsumerGetsEveryFrameInOrder) {
  std::atomic<std::size_t> taken{0};
  LiveCapture capture(std::make_unique<FakeSource>(50, 2ms, false, &taken));
  const auto got = take_all(capture, 0ms, &taken);
  ASSERT_EQ(got.size(), 50u);
  for (std::size_t i = 0; i < got.size(); ++i) {
    EXPECT_EQ(got[i].index, i);
    EXPECT_EQ(got[i].left.at<std::uint8_t>(0, 0), i);
    EXPECT_DOUBLE_EQ(got[i].timestamp, 0.001 * static_cast<double>(i));
    EXPECT_EQ(got[i].left_path, "/dev/fake");
  }
  EXPECT_EQ(capture.dropped(), 0u);
  EXPECT_EQ(capture.captured(), 50u);
  EXPECT_EQ(capture.taken(), 50u);
}

TEST(LiveCapture, ASlowConsumerGetsTheNewestFrameAndDropsAreCounted) {
  // The source delivers every 0.2 ms, tracking takes 5 ms a frame: most frames must be dropped.
  LiveCapture capture(std::make_unique<FakeSource>(400, 200us));
  const auto got = take_all(capture, 5ms);
  ASSERT_GE(got.size(), 2u);
  EXPECT_EQ(capture.captured(), 400u);
  EXPECT_GT(capture.dropped(), 200u);
  // Every captured frame was either taken or dropped, and the indices show where.
  EXPECT_EQ(capture.taken() + capture.dropped(), capture.captured());
  std::size_t gaps = got.front().index;
  for (std::size_t k = 1; k < got.size(); ++k) {
    ASSERT_GT(got[k].index, got[k - 1].index);
    gaps += got[k].index - got[k - 1].index - 1;
    EXPECT_EQ(got[k].left.at<std::uint8_t>(0, 0), got[k].index % 256);  // the frame its index says
  }
  EXPECT_EQ(gaps + 399 - got.back().index, capture.dropped());
  // The last frame is never lost: it is the newest when the source ends.
  EXPECT_EQ(got.back().index, 399u);
}

TEST(LiveCapture, CaptureGoesOnWhileNobodyTakes) {
  auto source = std::make_unique<FakeSource>(1000000, 100us);
  auto& delivered = source->delivered();
  LiveCapture capture(std::move(source));
  // Tracking busy for 200 ms: the capture thread must keep taking frames from the camera.
  std::this_thread::sleep_for(200ms);
  const std::size_t during = delivered.load();
  EXPECT_GT(during, 100u);
  auto f = capture.next(1000ms);
  ASSERT_TRUE(f);
  EXPECT_GE(f->index + 2, during);  // the newest frame, not the first
  EXPECT_GE(capture.dropped(), f->index);
  // Stopping does not wait for anybody to take frames.
  const auto t0 = std::chrono::steady_clock::now();
  capture.stop();
  EXPECT_LT(std::chrono::steady_clock::now() - t0, 500ms);
  EXPECT_GE(capture.captured(), capture.taken() + capture.dropped());
  EXPECT_LE(capture.captured() - capture.taken() - capture.dropped(), 1u);  // at most one left in the slot
}

TEST(LiveCapture, NextWaitsNoLongerThanItsTimeout) {
  LiveCapture capture(std::make_unique<FakeSource>(1, 500ms));  // a camera delivering nothing for 0.5 s
  const auto t0 = std::chrono::steady_clock::now();
  EXPECT_FALSE(capture.next(50ms));
  const auto waited = std::chrono::steady_clock::now() - t0;
  EXPECT_GE(waited, 45ms);
  EXPECT_LT(waited, 400ms);
  EXPECT_FALSE(capture.ended());
}

TEST(LiveCapture, ASourceErrorReachesTheConsumerAfterItsFrames) {
  LiveCapture capture(std::make_unique<FakeSource>(3, 1ms, true));
  std::size_t frames = 0;
  try {
    for (int tries = 0; tries < 100; ++tries) {
      if (capture.next(100ms)) ++frames;
    }
    ADD_FAILURE() << "no error";
  } catch (const InputError& e) {
    EXPECT_EQ(std::string(e.what()), "/dev/fake: no frame: the camera stopped delivering (unplugged?)");
  }
  EXPECT_GE(frames, 1u);
  EXPECT_EQ(frames + capture.dropped(), 3u);
  EXPECT_TRUE(capture.ended());
  EXPECT_FALSE(capture.next(1ms));  // reported once
}

}  // namespace live_capture_test
}  // namespace plslam::io
