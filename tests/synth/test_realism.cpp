// The images must look like a camera's and carry the features the SLAM front end needs:
// office and street rich in corners and lines, the corridor poor in corners but still rich in
// lines. Frames are spread over a whole loop of each scene and saved as artefacts.
#include <gtest/gtest.h>

#include <cstdlib>

#include <fmt/format.h>
#include <opencv2/features2d.hpp>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>

#include "plslam/synth/sequence.h"
#include "support/test_support.h"

namespace plslam::synth {
namespace {

struct Counts {
  int fast = 0;
  int lsd_long = 0;
};

Counts count_features(const cv::Mat& img) {
  Counts c;
  std::vector<cv::KeyPoint> kps;
  cv::FAST(img, kps, 20, true);
  c.fast = static_cast<int>(kps.size());
  auto lsd = cv::createLineSegmentDetector(cv::LSD_REFINE_STD);
  std::vector<cv::Vec4f> lines;
  lsd->detect(img, lines);
  for (const auto& l : lines)
    if (std::hypot(l[2] - l[0], l[3] - l[1]) > 30) ++c.lsd_long;
  return c;
}

struct Case {
  SceneKind scene;
  CameraPreset preset;
  int frames;
};

std::vector<Counts> run_scene(const Case& c, int samples) {
  SequenceOptions o;
  o.scene = c.scene;
  o.preset = c.preset;
  o.frames = c.frames;
  o.loop = true;
  o.seed = 1;
  const Sequence seq(o);
  StereoRenderer r(seq);
  std::vector<Counts> out;
  for (int k = 0; k < samples; ++k) {
    const std::size_t i = static_cast<std::size_t>(k) * (seq.size() - 1) / samples;
    const auto im = r.render(i);
    out.push_back(count_features(im.left));
    const std::string name = fmt::format("synth_{}_{}_{:03d}.png", to_string(c.scene), c.preset.name, i);
    if (samples <= 16) cv::imwrite((test::artifacts_dir() / name).string(), im.left);
    if (k == 1 && samples <= 16) {
      cv::Mat pair;
      cv::hconcat(im.left, im.right, pair);
      cv::imwrite((test::artifacts_dir() / fmt::format("synth_{}_{}_stereo.png", to_string(c.scene), c.preset.name)).string(), pair);
    }
    std::printf("%s/%s frame %zu: FAST(20) %d, LSD > 30 px %d\n", to_string(c.scene), c.preset.name.c_str(), i,
                out.back().fast, out.back().lsd_long);
  }
  return out;
}

// 8 frames per loop by default; PLSLAM_SYNTH_REALISM_SAMPLES=N checks N (e.g. every frame).
const int kSamples = std::getenv("PLSLAM_SYNTH_REALISM_SAMPLES") ? std::atoi(std::getenv("PLSLAM_SYNTH_REALISM_SAMPLES")) : 8;

TEST(SynthRealism, OfficeIsRichInCornersAndLines) {
  for (const auto& c : run_scene({SceneKind::kOffice, euroc_preset(), 470}, kSamples)) {
    EXPECT_GE(c.fast, 300);
    EXPECT_GE(c.lsd_long, 50);
  }
}

TEST(SynthRealism, StreetIsRichInCornersAndLines) {
  for (const auto& c : run_scene({SceneKind::kStreet, kitti_preset(), 200}, kSamples)) {
    EXPECT_GE(c.fast, 300);
    EXPECT_GE(c.lsd_long, 50);
  }
}

TEST(SynthRealism, CorridorHasLinesButFewCorners) {
  for (const auto& c : run_scene({SceneKind::kCorridor, euroc_preset(), 800}, kSamples)) {
    EXPECT_LT(c.fast, 150);
    EXPECT_GE(c.lsd_long, 30);
  }
}

TEST(SynthRealism, ImageStatisticsLikeACamera) {
  // Not saturated, not black, uses a wide grey range, and has sensor noise in flat areas.
  SequenceOptions o;
  o.frames = 20;
  const Sequence seq(o);
  StereoRenderer r(seq);
  const auto im = r.render(10);
  cv::Scalar mean, stddev;
  cv::meanStdDev(im.left, mean, stddev);
  EXPECT_GT(mean[0], 60);
  EXPECT_LT(mean[0], 190);
  EXPECT_GT(stddev[0], 25);
  EXPECT_LT(cv::countNonZero(im.left >= 255), static_cast<int>(im.left.total() / 4));
  // Noise: the Laplacian of a rendered image is never exactly zero over large areas.
  cv::Mat lap;
  cv::Laplacian(im.left, lap, CV_16S);
  EXPECT_GT(cv::countNonZero(lap), static_cast<int>(im.left.total() * 0.7));
}

}  // namespace
}  // namespace plslam::synth
