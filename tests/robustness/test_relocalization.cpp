// Relocalization on real images (issue 14): the KITTI 06 excerpt replayed as a kidnapped robot
// (frames 0-50, 20 black frames, then frames 10-50 again: the camera reappears 50 m back), and
// the fallbacks: without place recognition, and when relocalization keeps failing, a new map
// segment; a bad vocabulary file is refused before the first frame.
#include <fstream>
#include <iostream>
#include <memory>

#include <fmt/format.h>
#include <gtest/gtest.h>
#include <opencv2/imgcodecs.hpp>
#include <nlohmann/json.hpp>

#include "plslam/eval/alignment.h"
#include "plslam/eval/ape.h"
#include "plslam/eval/association.h"
#include "plslam/eval/frame_log.h"
#include "plslam/io/trajectory_io.h"
#include "robustness/kitti_copies.h"
#include "support/test_support.h"

namespace plslam {
namespace {

namespace fs = std::filesystem;

constexpr long kTextureReturns = 71;  // first frame of the replay

// Frames 0..50, 20 black frames, then frames 10..replay_last again, at 10 Hz. (With a shorter
// first pass, 0-30 then 10-30, the camera is not lost: the reference keyframe's far points still
// place it.) The tests that only need the first frames after the return replay fewer: each frame
// costs ~1 s under the sanitizers of CI.
fs::path kidnapped_copy(const fs::path& data, const fs::path& root, int replay_last = 50) {
  auto frames = test::range(0, 51);
  for (int i = 0; i < 20; ++i) frames.push_back(-1);
  for (int i = 10; i <= replay_last; ++i) frames.push_back(i);
  return test::make_copy(data, root, frames, {}, "06", /*times_at_10hz=*/true);
}


// frames.csv's state column by frame id (the black frames are skipped and have no row).
std::map<long, std::string> states_by_frame(const fs::path& run) {
  const auto log = eval::read_frame_log(run / "frames.csv");
  const auto col = [&](const char* name) {
    return static_cast<std::size_t>(std::find(log.header.begin(), log.header.end(), name) - log.header.begin());
  };
  std::map<long, std::string> out;
  for (const auto& row : log.rows) out[std::stol(row[col("frame")])] = row[col("state")];
  return out;
}

// Position error of every tracked frame (by input index) after the se3 alignment of the run.
std::map<std::size_t, double> errors_by_frame(const test::Run& r, const fs::path& gt_file) {
  const auto est = io::read_trajectory(r.out / "trajectory.kitti", io::TrajectoryFormat::kKitti);
  const auto gt = io::read_trajectory(gt_file, io::TrajectoryFormat::kKitti);
  const auto untracked = r.stats["untracked_kitti_lines"].get<std::vector<std::size_t>>();
  EXPECT_EQ(est.size(), gt.size());
  Trajectory e, g;
  std::vector<std::size_t> index;
  for (std::size_t i = 0; i < std::min(est.size(), gt.size()); ++i) {
    if (std::find(untracked.begin(), untracked.end(), i) != untracked.end()) continue;
    e.push_back(est[i]);
    g.push_back(gt[i]);
    index.push_back(i);
  }
  const auto aligned = eval::apply_alignment(e, eval::solve_alignment(g, e, eval::AlignMode::kSE3));
  const auto err = eval::ape_translation(g, aligned);
  std::map<std::size_t, double> out;
  for (std::size_t k = 0; k < index.size(); ++k) out[index[k]] = err[k];
  return out;
}

TEST(Relocalization, KidnappedKittiCameraIsFoundAgainInTheSameMap) {
  PLSLAM_REQUIRE_SHARED_DATA(data);
  test::TempDir tmp;
  const auto seq = kidnapped_copy(data, tmp.path() / "d");
  const auto r = test::run(seq, tmp.path() / "out");
  ASSERT_EQ(r.cli.exit_code, 0) << r.cli.err;
  EXPECT_EQ(r.stats["skipped_frames"], 20);  // the black frames, reported
  EXPECT_EQ(r.stats["new_map_segments"]["count"], 0);
  const auto reloc = r.stats["relocalizations"]["frames"].get<std::vector<long>>();
  ASSERT_EQ(reloc.size(), 1u) << r.stats.dump(2);
  // Within 3 frames of texture returning, and confirmed within 3 frames too: the frames between
  // recover (KITTI preset: 3 frames), then tracking goes on.
  EXPECT_GE(reloc.front(), kTextureReturns);
  EXPECT_LT(reloc.front(), kTextureReturns + 3);
  const auto states = states_by_frame(r.out);
  long confirmed = -1;
  for (const auto& [frame, state] : states) {
    if (frame < reloc.front()) {
      EXPECT_EQ(state, frame < 51 ? "tracked" : "lost") << frame;
    } else if (confirmed < 0 && state == "relocalized") {
      confirmed = frame;
    } else {
      EXPECT_EQ(state, confirmed < 0 ? "recovering" : "tracked") << frame;
    }
  }
  EXPECT_LT(confirmed, kTextureReturns + 3);
  EXPECT_EQ(r.stats["frame_states"]["recovering"], confirmed - reloc.front());
  EXPECT_EQ(r.stats["place_recognition"]["enabled"], true);
  EXPECT_GT(r.stats["place_recognition"]["database_keyframes"].get<int>(), 5);
  // Every replayed frame from the confirmed relocalization on is where the ground truth says, in
  // the world frame of the first pass (the recovering frames are not trusted lines).
  const auto errors = errors_by_frame(r, tmp.path() / "d" / "poses" / "06.txt");
  std::size_t replayed = 0;
  for (const auto& [frame, err] : errors) {
    if (static_cast<long>(frame) < reloc.front()) continue;
    ++replayed;
    EXPECT_LT(err, 0.2) << "frame " << frame;
  }
  EXPECT_EQ(replayed, static_cast<std::size_t>(kTextureReturns + 41 - confirmed));
  EXPECT_NE(r.cli.out.find("relocalizations 1, new map segments 0"), std::string::npos) << r.cli.out;
  // Loop detection skips a place relocalization already tied to the map; a global BA joins the
  // replay's keyframes to the first pass's instead (issue 15). Whole run: 0.032 m measured.
  EXPECT_EQ(r.stats["loop_closing"]["global_ba_after_relocalization"], 1);
  EXPECT_GE(r.stats["global_ba_runs"].get<int>(), 1);
  EXPECT_LT(r.stats["accuracy"]["ape_trans_m"]["rmse"].get<double>(), 0.05);
}

// The same in the default (deterministic) mode: local mapping fills the keyframe database on its
// own thread beside the next frame's extraction (this suite also runs under ThreadSanitizer).
TEST(RelocalizationConcurrent, KidnappedKittiCameraIsFoundAgainWhileLocalMappingRuns) {
  PLSLAM_REQUIRE_SHARED_DATA(data);
  test::TempDir tmp;
  const auto seq = kidnapped_copy(data, tmp.path() / "d", 30);  // 21 replayed frames
  const fs::path out = tmp.path() / "out";
  const auto cli = test::run_cli("run \"" + seq.string() + "\" --out \"" + out.string() + "\" --quiet");
  ASSERT_EQ(cli.exit_code, 0) << cli.err;
  const auto stats = nlohmann::json::parse(test::read_file(out / "stats.json"));
  EXPECT_EQ(stats["mode"], "deterministic");
  EXPECT_EQ(stats["new_map_segments"]["count"], 0);
  const auto reloc = stats["relocalizations"]["frames"].get<std::vector<long>>();
  ASSERT_EQ(reloc.size(), 1u) << stats.dump(2);
  EXPECT_LT(reloc.front(), kTextureReturns + 3);
  // Every frame from the relocalization's confirmation on is tracked: the KITTI preset trusts the
  // third frame of a relocalization (confirm_frames 3). Which replayed frame relocalizes first
  // depends on how far local mapping has filled the database (frame 72 on a loaded machine).
  const long untrusted_replay = reloc.front() - kTextureReturns + 2;
  EXPECT_GE(stats["tracked_frames"].get<long>(), 51 + 21 - untrusted_replay);
  // The global BA after the revisit runs in its own thread beside tracking and local mapping.
  EXPECT_EQ(stats["loop_closing"]["global_ba_after_relocalization"], 1);
  EXPECT_EQ(stats["global_ba_runs"].get<int>() + stats["global_ba_aborted"].get<int>(), 1);
}

// After 1 s of black frames the motion model is a second out of date, and the rendered office
// (seed 1) offers look-alike places: its shelves hold the same books on both faces. Whatever the
// system does after the black-out (track on, relocalize, start a new map segment), every pose it
// gives in the map it had must be where the camera is. Two black-outs that each ended elsewhere,
// with exit 0 and one warning at most:
// - frames 120-139: frame 140 was tracked 2 m and 17 deg from the prediction with 46 inliers (a
//   suspect jump, reported and kept) and the rest of the run followed it (ATE 1.54 m);
// - frames 300-319: the camera comes back facing what the map has not seen, and frame 335
//   relocalized against a shelf 4 m away with 86 inliers (ATE 2.9 m).
// Now frame 140 is found where it is, and 300-319 ends in a new map segment. How frame 140 is found
// depends on the matches of that one frame: with right-image lines from a second detection it was
// lost and relocalized; with guided stereo lines the wide motion-model search tracks it (202
// inliers, 0.19 m and 16 deg from the stale prediction, reported as a suspect jump). Either is right.
class BlackOut : public ::testing::Test {
 protected:
  static void SetUpTestSuite() {
    tmp_ = std::make_unique<test::TempDir>();
    const auto synth = test::run_cli("synth --out \"" + office().string() +
                                     "\" --scene office --preset euroc --frames 480 --loop --seed 1 --threads 2");
    ASSERT_EQ(synth.exit_code, 0) << synth.err;
  }
  static void TearDownTestSuite() { tmp_.reset(); }
  static fs::path office() { return tmp_->path() / "office"; }

  // Frames black_from..black_from+19 black, run up to `frames` frames; checks every pose of
  // trajectory.tum after the black-out against the ground truth, aligned on the frames before it
  // (a new map segment's frames are unanchored, not in it). Returns the run's stats.
  static nlohmann::json run_with_black_out(std::size_t black_from, std::size_t frames) {
    const fs::path seq = tmp_->path() / fmt::format("black-{}", black_from);
    fs::create_directories(seq / "mav0");
    // Vision only, as these frame-exact cases were measured: with the IMU, the world turns to the
    // gravity-aligned one at 5 s, which changes the rounding of every later solve, and with it
    // which of two right answers the run takes after a black-out (frame 440: tracked across it
    // instead of relocalized, its loop at 464).
    for (const auto& e : fs::directory_iterator(office() / "mav0")) {
      if (e.path().filename() != "imu0") fs::create_directory_symlink(e.path(), seq / "mav0" / e.path().filename());
    }
    for (const char* cam : {"cam0", "cam1"}) {  // own copies of the camera folders, images linked
      const fs::path dst = seq / "mav0" / cam;
      fs::remove(dst);
      fs::create_directories(dst / "data");
      fs::copy_file(office() / "mav0" / cam / "data.csv", dst / "data.csv");
      fs::copy_file(office() / "mav0" / cam / "sensor.yaml", dst / "sensor.yaml");
      std::vector<fs::path> images;
      for (const auto& e : fs::directory_iterator(office() / "mav0" / cam / "data")) images.push_back(e.path());
      std::sort(images.begin(), images.end(), [](const fs::path& a, const fs::path& b) {
        return std::stoll(a.stem().string()) < std::stoll(b.stem().string());
      });
      EXPECT_EQ(images.size(), 480u);
      const cv::Mat black = cv::Mat::zeros(cv::imread(images.front().string(), cv::IMREAD_GRAYSCALE).size(), CV_8U);
      for (std::size_t i = 0; i < images.size(); ++i) {
        const fs::path to = dst / "data" / images[i].filename();
        if (i >= black_from && i < black_from + 20) {
          EXPECT_TRUE(cv::imwrite(to.string(), black));
        } else {
          fs::create_symlink(images[i], to);
        }
      }
    }
    const auto r = test::run(seq, tmp_->path() / fmt::format("out-{}", black_from), fmt::format("--max-frames {}", frames));
    EXPECT_EQ(r.cli.exit_code, 0) << r.cli.err;
    if (r.stats.is_null()) return r.stats;
    const auto est = io::read_trajectory(r.out / "trajectory.tum", io::TrajectoryFormat::kTum);
    const auto gt = io::read_trajectory(office() / "mav0" / "synth" / "left_camera.tum", io::TrajectoryFormat::kTum);
    std::vector<double> gt_t, est_t;
    for (const auto& p : gt) gt_t.push_back(p.t);
    for (const auto& p : est) est_t.push_back(p.t);
    const auto pairs = eval::associate_by_time(gt_t, est_t, 0.01);
    Trajectory g, e;
    for (std::size_t k = 0; k < pairs.size(); ++k) {
      if (gt[pairs.gt[k]].t >= gt.at(black_from).t) continue;
      g.push_back(gt[pairs.gt[k]]);
      e.push_back(est[pairs.est[k]]);
    }
    EXPECT_GT(g.size(), black_from - 5);
    const auto aligned = eval::apply_alignment(est, eval::solve_alignment(g, e, eval::AlignMode::kSE3));
    std::size_t checked = 0;
    for (std::size_t k = 0; k < pairs.size(); ++k) {
      const double t = gt[pairs.gt[k]].t;
      if (t < gt.at(black_from).t) continue;
      ++checked;
      const double error = (aligned[pairs.est[k]].T.translation() - gt[pairs.gt[k]].T.translation()).norm();
      EXPECT_LT(error, 0.3) << "frame at t = " << t << " is " << error << " m from where the camera is";
    }
    std::cout << "black-out from frame " << black_from << ": " << checked << " poses after it checked, relocalized "
              << r.stats["relocalizations"]["frames"].dump() << ", new segments " << r.stats["new_map_segments"]["frames"].dump()
              << "\n";
    return r.stats;
  }

  static std::unique_ptr<test::TempDir> tmp_;
};

std::unique_ptr<test::TempDir> BlackOut::tmp_;

TEST_F(BlackOut, AJumpToALookAlikePlaceIsNotTakenAfterABlackOut) {
  const auto stats = run_with_black_out(120, 180);
  ASSERT_FALSE(stats.is_null());
  // The same map goes on (the poses after the black-out are checked in run_with_black_out), and
  // every frame that is not black has a pose: the first ones after the black-out recover until
  // the EuRoC preset's 5 frames confirm them (a frame 1 s after the one before it is not trusted at
  // once, tracking.recover_after_gap_s), and every later one is trusted.
  EXPECT_EQ(stats["new_map_segments"]["count"], 0);
  EXPECT_EQ(stats["frame_states"]["lost"].get<int>(), 0);
  EXPECT_EQ(stats["frame_states"]["recovering"].get<int>(), 4);
  EXPECT_EQ(stats["tracked_frames"].get<int>(), 156);
}

TEST_F(BlackOut, ALookAlikePlaceIsNotTakenForTheCamerasPlace) {
  const auto stats = run_with_black_out(300, 346);
  ASSERT_FALSE(stats.is_null());
  // The scene does what this test is about: the camera is lost after the black-out.
  EXPECT_GE(stats["lost_events"].get<int>(), 1);
  EXPECT_GE(stats["relocalizations"]["count"].get<int>() + stats["new_map_segments"]["count"].get<int>(), 1);
  // A new segment's frames, placed by the stale motion model, are unanchored to the end (no loop
  // ties them before frame 346): none of them is a trusted pose.
  const auto segments = stats["new_map_segments"]["frames"].get<std::vector<long>>();
  if (!segments.empty()) {
    EXPECT_EQ(stats["frame_states"]["unanchored"].get<long>(), 346 - segments.front());
    EXPECT_EQ(stats["tracked_frames"].get<long>(),
              stats["frame_states"]["tracked"].get<long>() + stats["frame_states"]["relocalized"].get<long>());
  }
}

// Frames 360-379 black: the camera turns 34 degrees in the dark, so frame 380 is found by
// relocalization against keyframe 150, the true place, not on the motion model's prediction. Its
// frames 381-383 hold inliers in 84-88 % of the image cells, frame 384 in 26 of 35 (0.743, under
// the preset's 0.75): one such miss is forgiven (relocalization.max_cell_misses) for one more frame,
// and the relocalization is confirmed at 386. Refuted at 384, the camera stayed lost until the
// revisit, the loop at 456 was never closed and the ATE was 2.28x that of the run without a black-out.
TEST_F(BlackOut, ATruePlaceThatFallsUnderTheCellsForOneFrameIsConfirmed) {
  const auto stats = run_with_black_out(360, 392);
  ASSERT_FALSE(stats.is_null());
  EXPECT_EQ(stats["relocalizations"]["frames"], nlohmann::json::array({380}));
  EXPECT_EQ(stats["lost_events"].get<int>(), 1);  // the tracking across the gap, refuted at 380
  EXPECT_EQ(stats["new_map_segments"]["count"], 0);
  EXPECT_EQ(stats["frame_states"]["recovering"].get<int>(), 6);  // 380-385, confirmed at 386
  EXPECT_EQ(stats["frame_states"]["lost"].get<int>(), 0);
}

// Frames 440-459 black: the camera comes back at the start of the loop, where the run without a
// black-out closes its loop (frame 456 -> 14). Relocalization ties the revisit to the start, but
// only the loop across the relocalization, from the last keyframe before the loss (frame 439; 438
// since the path became smooth to second order, 2026-11-30) to the start, ties the drifted end of
// the path to it: ATE 0.0072 m against 0.0069 m without the black-out, 0.0201 m (2.9x) without
// that loop.
TEST_F(BlackOut, ALossThatHidesTheLoopIsClosedAcrossTheRelocalization) {
  const auto stats = run_with_black_out(440, 480);
  ASSERT_FALSE(stats.is_null());
  EXPECT_EQ(stats["relocalizations"]["count"], 1);
  EXPECT_EQ(stats["loop_closing"]["loops_across_relocalization"], 1);
  ASSERT_EQ(stats["loops"].size(), 1u);
  const long loop_frame = stats["loops"][0]["frame"].get<long>();
  EXPECT_GE(loop_frame, 430);  // the last keyframes before the loss
  EXPECT_LT(loop_frame, 440);
  EXPECT_LT(stats["accuracy"]["ape_trans_m"]["rmse"].get<double>(), 1.5 * 0.0069);
}

TEST(Relocalization, WithoutPlaceRecognitionALostCameraStartsANewSegment) {
  PLSLAM_REQUIRE_SHARED_DATA(data);
  test::TempDir tmp;
  const auto seq = kidnapped_copy(data, tmp.path() / "d", 15);  // to frame 76
  const auto map_file = tmp.path() / "m.plmap";
  const auto r = test::run(seq, tmp.path() / "out", "--no-place-recognition --save-map \"" + map_file.string() + "\"");
  ASSERT_EQ(r.cli.exit_code, 0) << r.cli.err;
  EXPECT_EQ(r.stats["relocalizations"]["count"], 0);
  EXPECT_EQ(r.stats["new_map_segments"]["frames"], nlohmann::json::array({kTextureReturns + 1}));
  EXPECT_EQ(r.stats["place_recognition"]["enabled"], false);
  // The segment starts where the motion model guessed, 1 s of darkness and a kidnapping later: its
  // frames (72-76) are unanchored, and trajectory.tum holds only the first segment's.
  const auto states = states_by_frame(r.out);
  for (long f = kTextureReturns + 1; f <= kTextureReturns + 5; ++f) EXPECT_EQ(states.at(f), "unanchored") << f;
  EXPECT_EQ(r.stats["frame_states"]["unanchored"], 5);
  EXPECT_EQ(r.stats["frame_states"]["tracked"], r.stats["tracked_frames"]);
  const auto tum = io::read_trajectory(r.out / "trajectory.tum", io::TrajectoryFormat::kTum);
  EXPECT_EQ(tum.size(), r.stats["tracked_frames"].get<std::size_t>());
  EXPECT_LT(tum.back().t, 0.1 * kTextureReturns - 0.05);  // (times at 10 Hz)
  // keyframes.tum and the map file leave the segment's keyframes out too.
  const auto keyframes = io::read_trajectory(r.out / "keyframes.tum", io::TrajectoryFormat::kTum);
  EXPECT_LT(keyframes.back().t, 0.1 * kTextureReturns - 0.05);
  EXPECT_LT(keyframes.size(), r.stats["keyframes"].get<std::size_t>());
  EXPECT_EQ(r.stats["map"]["save"]["keyframes"].get<std::size_t>(), keyframes.size());
}

TEST(Relocalization, KeepsFailingForOneSecondThenStartsANewSegment) {
  PLSLAM_REQUIRE_SHARED_DATA(data);
  test::TempDir tmp;
  const auto seq = kidnapped_copy(data, tmp.path() / "d", 24);  // to frame 85
  // An unreachable inlier threshold: relocalization can never succeed.
  {
    std::ofstream c(tmp.path() / "c.yaml");
    c << "relocalization:\n  min_inliers: 100000\n  new_segment_after_s: 1.0\n";
  }
  const auto r = test::run(seq, tmp.path() / "out", "--config \"" + (tmp.path() / "c.yaml").string() + "\"");
  ASSERT_EQ(r.cli.exit_code, 0) << r.cli.err;
  EXPECT_EQ(r.stats["relocalizations"]["count"], 0);
  // Lost at 71; the textured frames 71-80 try to relocalize, frame 81 (1 s later) starts a segment.
  EXPECT_EQ(r.stats["new_map_segments"]["frames"], nlohmann::json::array({kTextureReturns + 10}));
  const auto lost = r.stats["lost_frame_ids"].get<std::vector<long>>();
  ASSERT_EQ(lost.size(), 10u);
  EXPECT_EQ(lost.front(), kTextureReturns);
  EXPECT_EQ(lost.back(), kTextureReturns + 9);
}

TEST(Relocalization, BadVocabularyFilesAreRefusedBeforeTheFirstFrame) {
  PLSLAM_REQUIRE_SHARED_DATA(data);
  test::TempDir tmp;
  const fs::path seq = data / "kitti" / "sequences" / "06";
  const std::string good = test::read_file(fs::path(PLSLAM_SOURCE_DIR) / "data" / "vocabulary" / "plslam_orb_k10_l4.plvoc");
  ASSERT_GT(good.size(), 1000u);
  {
    std::ofstream(tmp.path() / "truncated.plvoc", std::ios::binary).write(good.data(), 500);
    std::ofstream(tmp.path() / "foreign.plvoc") << "# ORB-SLAM2 vocabulary\n10 6 0 0\n";
  }
  for (const std::string name : {"missing.plvoc", "truncated.plvoc", "foreign.plvoc"}) {
    const fs::path file = tmp.path() / name;
    const auto r = test::run_cli("run \"" + seq.string() + "\" --out \"" + (tmp.path() / ("out-" + name)).string() +
                                 "\" --quiet --vocabulary \"" + file.string() + "\"");
    EXPECT_EQ(r.exit_code, 2) << name;
    EXPECT_NE(r.err.find(file.string()), std::string::npos) << r.err;
    EXPECT_EQ(std::count(r.err.begin(), r.err.end(), '\n'), 1) << r.err;
    EXPECT_FALSE(fs::exists(tmp.path() / ("out-" + name) / "stats.json"));
  }
}

TEST(Relocalization, VocabInfoPrintsTheDefaultVocabularysParameters) {
  const fs::path file = fs::path(PLSLAM_SOURCE_DIR) / "data" / "vocabulary" / "plslam_orb_k10_l4.plvoc";
  const auto text = test::run_cli("vocab info \"" + file.string() + "\"");
  ASSERT_EQ(text.exit_code, 0) << text.err;
  EXPECT_NE(text.out.find("k = 10, L = 4"), std::string::npos) << text.out;
  const auto json = test::run_cli("vocab info \"" + file.string() + "\" --json");
  ASSERT_EQ(json.exit_code, 0) << json.err;
  const auto j = nlohmann::json::parse(json.out);
  EXPECT_EQ(j["k"], 10);
  EXPECT_EQ(j["levels"], 4);
  EXPECT_GT(j["words"].get<int>(), 5000);
  EXPECT_LT(j["bytes"].get<double>(), 10e6);
  EXPECT_EQ(test::run_cli("vocab info \"" + (file.string() + ".missing") + "\"").exit_code, 2);
}

}  // namespace
}  // namespace plslam
