// plslam/plslam.h: what an embedding program sees.
#include <algorithm>
#include <unistd.h>

#include <fstream>
#include <string>

#include <gtest/gtest.h>

#include <opencv2/imgproc.hpp>

#include "plslam/plslam.h"
#include "plslam/system/slam_system.h"
#include "support/test_support.h"

namespace plslam {
namespace {

// 60 frames of the rendered office (EuRoC layout, exact ground truth), rendered once per build.
// ctest runs each test as its own process, and two may get here at once: each renders into its own
// folder and renames it into place, so the shared folder is either absent or whole.
const std::filesystem::path& api_sequence() {
  static const std::filesystem::path dir = [] {
    const auto d = test::artifacts_dir() / "public_api_office60";
    const auto whole = [](const std::filesystem::path& p) { return std::filesystem::exists(p / "mav0/synth/synth.json"); };
    if (whole(d)) return d;
    auto own = d;
    own += ".part-" + std::to_string(::getpid());
    std::filesystem::remove_all(own);
    const auto r = test::run_cli("synth --out \"" + own.string() + "\" --scene office --preset euroc --frames 60 --seed 1");
    EXPECT_EQ(r.exit_code, 0) << r.err;
    if (r.exit_code != 0) return own;  // never put a failed render in the shared place
    std::error_code ec;
    std::filesystem::rename(own, d, ec);
    if (!ec) return d;
    if (whole(d)) {  // another process renamed its copy first
      std::filesystem::remove_all(own);
      return d;
    }
    return own;  // something else is in the way: use this process's copy
  }();
  return dir;
}

SlamOptions sequential_options(const Sequence& seq) {
  SlamOptions o;
  o.preset = seq.preset();
  o.sequential = true;
  return o;
}

TEST(PublicApi, TracksASequenceWithPosesTheTrajectoryAndMapAgreeOn) {
  const Sequence seq(api_sequence());
  ASSERT_EQ(seq.size(), 60u);
  ASSERT_NE(seq.ground_truth(), nullptr);
  Slam slam(seq.calibration(), sequential_options(seq));
  long changes_seen = slam.map_changes();
  for (std::size_t i = 0; i < seq.size(); ++i) {
    const auto images = seq.frame(i);
    const auto f = slam.track(images.left, images.right, images.timestamp);
    ASSERT_TRUE(f.tracked) << "frame " << i;
    EXPECT_EQ(f.index, static_cast<long>(i));
    EXPECT_EQ(f.state, TrackingState::kTracking);
    // The pose returned is the trajectory's last pose at this moment.
    const auto traj = slam.trajectory();
    ASSERT_EQ(traj.size(), i + 1);
    EXPECT_TRUE(traj.back().T.isApprox(f.T_world_camera, 1e-12));
    if (f.keyframe) {
      EXPECT_NE(slam.map_changes(), changes_seen) << "a new keyframe changes the map";
      changes_seen = slam.map_changes();
    }
  }
  slam.shutdown();
  EXPECT_TRUE(slam.is_shut_down());

  const auto stats = slam.stats();
  EXPECT_EQ(stats.frames, 60);
  EXPECT_EQ(stats.tracked, 60);
  const auto map = slam.map();
  EXPECT_EQ(static_cast<std::size_t>(map.points.rows()), stats.points);
  EXPECT_EQ(static_cast<std::size_t>(map.lines.rows()), stats.lines);
  EXPECT_EQ(map.point_ids.size(), stats.points);
  EXPECT_EQ(map.keyframes.size(), stats.keyframes);
  EXPECT_EQ(map.changes, slam.map_changes());
  EXPECT_GT(stats.points, 500u);
  EXPECT_GT(stats.lines, 20u);

  const auto errors = evaluate_trajectory(*seq.ground_truth(), slam.trajectory());
  EXPECT_EQ(errors.pairs, 60u);
  EXPECT_LT(errors.ate_rmse_m, 0.02);
}

// deterministic: mapping on its own thread, met at frames fixed in advance. track() returns each
// pose before its keyframe's local mapping (which still runs then), the same in every run; with
// the local BA met before the next frame (a config file's mapping.ba_merge_after_frames: 1, and
// ba_merge_ms_per_1000_observations: 0, so not later for a large window), the
// final trajectory is sequential's, bit for bit (no loop in 60 frames).
TEST(PublicApi, DeterministicTrackingIsReproducibleAndWithAOneFrameLagEndsWithTheSequentialTrajectory) {
  const Sequence seq(api_sequence());
  test::TempDir tmp;
  const auto lag1 = tmp.path() / "lag1.yaml";
  std::ofstream(lag1) << "mapping:\n  ba_merge_after_frames: 1\n  ba_merge_ms_per_1000_observations: 0\n";
  struct Run {
    std::vector<Eigen::Isometry3d> returned;
    Trajectory final;
  };
  auto run = [&](bool deterministic, bool one_frame_lag) {
    auto o = sequential_options(seq);
    o.sequential = !deterministic;
    o.deterministic = deterministic;
    if (one_frame_lag) o.config_file = lag1;
    Slam slam(seq.calibration(), o);
    Run r;
    for (std::size_t i = 0; i < seq.size(); ++i) {
      const auto images = seq.frame(i);
      r.returned.push_back(slam.track(images.left, images.right, images.timestamp).T_world_camera);
    }
    slam.shutdown();
    EXPECT_GT(slam.stats().keyframes, 3u);
    r.final = slam.trajectory();
    return r;
  };
  const auto a = run(true, false);
  const auto b = run(true, false);
  ASSERT_EQ(a.returned.size(), b.returned.size());
  for (std::size_t i = 0; i < a.returned.size(); ++i) {
    EXPECT_TRUE(a.returned[i].matrix() == b.returned[i].matrix()) << "frame " << i;
  }
  EXPECT_LT(evaluate_trajectory(*seq.ground_truth(), a.final).ate_rmse_m, 0.02);
  const auto one = run(true, true);
  const auto s = run(false, true);
  ASSERT_EQ(one.final.size(), s.final.size());
  for (std::size_t i = 0; i < one.final.size(); ++i) {
    EXPECT_TRUE(one.final[i].T.matrix() == s.final[i].T.matrix()) << "frame " << i;
  }
}

TEST(PublicApi, RefusesBadImagesTimestampsAndCallsAfterShutdown) {
  const Sequence seq(api_sequence());
  Slam slam(seq.calibration(), sequential_options(seq));
  const auto a = seq.frame(0);
  EXPECT_THROW(slam.track(a.left(cv::Rect(0, 0, 100, 100)), a.right, a.timestamp), InputError);
  EXPECT_THROW(slam.track(cv::Mat(), a.right, a.timestamp), InputError);
  cv::Mat wrong_type;
  a.left.convertTo(wrong_type, CV_32F);
  EXPECT_THROW(slam.track(wrong_type, a.right, a.timestamp), InputError);
  cv::Mat bgr;
  cv::cvtColor(a.left, bgr, cv::COLOR_GRAY2BGR);
  EXPECT_TRUE(slam.track(bgr, a.right, a.timestamp).tracked);  // colour is converted
  EXPECT_THROW(slam.track(a.left, a.right, a.timestamp), InputError);  // not after the previous one
  slam.shutdown();
  EXPECT_THROW(slam.track(a.left, a.right, a.timestamp + 1), std::logic_error);
}

TEST(PublicApi, RefusesABadCalibrationWithTheFileNamed) {
  StereoCalibration bad{752, 480, 450, 450, 376, 240, 0.0};
  EXPECT_THROW(Slam{bad}, InputError);
  test::TempDir tmp;
  const auto file = tmp.path() / "stereo.yaml";
  std::ofstream(file) << "width: 752\nheight: 480\nfx: 450\nfy: 450\ncx: 376\ncy: 240\nbaseline: 0.11\n";
  const auto c = read_calibration(file);
  EXPECT_EQ(c.width, 752);
  EXPECT_DOUBLE_EQ(c.baseline, 0.11);
  std::ofstream(file) << "width: 752\nheight: 480\nfx: 450\nfy: 450\ncx: 376\ncy: 240\nbaseline: -1\n";
  try {
    read_calibration(file);
    FAIL() << "a negative baseline was accepted";
  } catch (const InputError& e) {
    EXPECT_EQ(e.file(), file.string());
  }
  EXPECT_THROW(Sequence(tmp.path() / "nothing_here"), InputError);
}

TEST(PublicApi, SavedMapIsLoadedAndLocalizedIn) {
  const Sequence seq(api_sequence());
  test::TempDir tmp;
  const auto file = tmp.path() / "office.plmap";
  {
    Slam slam(seq.calibration(), sequential_options(seq));
    for (std::size_t i = 0; i < seq.size(); ++i) {
      const auto im = seq.frame(i);
      slam.track(im.left, im.right, im.timestamp);
    }
    slam.save_map(file);
    EXPECT_TRUE(slam.is_shut_down());
  }
  auto options = sequential_options(seq);
  options.localization_only = true;
  Slam slam(seq.calibration(), options);
  slam.load_map(file);
  const auto keyframes = slam.stats().keyframes;
  EXPECT_GT(keyframes, 0u);
  // Every third frame: not the mapping run's input. The first is relocalized in the map, and the
  // frames recover from it until it is confirmed (EuRoC preset: 5 frames); from then on
  // every frame is localized, a trusted pose.
  std::vector<FrameState> states;
  for (std::size_t i = 0; i < seq.size(); i += 3) {
    const auto im = seq.frame(i);
    const auto f = slam.track(im.left, im.right, im.timestamp);
    EXPECT_EQ(f.tracked, f.frame_state == FrameState::kLocalized) << i;
    states.push_back(f.frame_state);
  }
  ASSERT_EQ(states.size(), 20u);
  const auto first = std::find(states.begin(), states.end(), FrameState::kLocalized) - states.begin();
  EXPECT_GE(first, 4);
  EXPECT_LE(first, 9);
  for (long i = 0; i < 20; ++i) {
    EXPECT_EQ(states[static_cast<std::size_t>(i)], i < first ? FrameState::kRecovering : FrameState::kLocalized) << i;
  }
  EXPECT_STREQ(to_string(FrameState::kRecovering), "recovering");
  EXPECT_EQ(slam.stats().keyframes, keyframes);  // localization adds nothing
  EXPECT_THROW(slam.load_map(file), std::logic_error);  // only before the first frame
}

}  // namespace
}  // namespace plslam
