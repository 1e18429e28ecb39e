// Rendered images agree with the ground truth: depth with the stereo disparity, projected 3D
// segments with image edges, and the trajectory with the motion limits.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>

#include <opencv2/imgproc.hpp>

#include "plslam/core/error.h"
#include "plslam/synth/sequence.h"

namespace plslam::synth {
namespace {

double median(std::vector<double> v) {
  std::nth_element(v.begin(), v.begin() + v.size() / 2, v.end());
  return v[v.size() / 2];
}

double percentile(std::vector<double> v, double p) {
  std::sort(v.begin(), v.end());
  return v[static_cast<std::size_t>(p * (v.size() - 1))];
}

// Measures the disparity at (x, y) by ZNCC over a (2r+1)^2 window, searching +-3 px around the
// prediction with parabolic sub-pixel refinement. NaN when the match is not distinctive.
double measure_disparity(const cv::Mat& L, const cv::Mat& R, int x, int y, double predicted, int r) {
  const cv::Mat wl = L(cv::Rect(x - r, y - r, 2 * r + 1, 2 * r + 1));
  const int d0 = static_cast<int>(std::round(predicted));
  std::vector<double> score;
  for (int d = d0 - 3; d <= d0 + 3; ++d) {
    const int xr = x - d;
    if (xr - r < 0 || xr + r >= R.cols) return NAN;
    cv::Mat res;
    cv::matchTemplate(R(cv::Rect(xr - r, y - r, 2 * r + 1, 2 * r + 1)), wl, res, cv::TM_CCOEFF_NORMED);
    score.push_back(res.at<float>(0, 0));
  }
  const auto best = std::max_element(score.begin() + 1, score.end() - 1) - score.begin();
  if (score[best] < 0.9) return NAN;
  const double a = score[best - 1], b = score[best], c = score[best + 1];
  const double denom = a - 2 * b + c;
  const double sub = std::abs(denom) > 1e-9 ? 0.5 * (a - c) / denom : 0.0;
  return d0 - 3 + static_cast<double>(best) + sub;
}

TEST(SynthGeometry, DepthAgreesWithStereoDisparity) {
  for (SceneKind scene : {SceneKind::kOffice, SceneKind::kStreet}) {
    SequenceOptions o;
    o.scene = scene;
    o.preset = scene == SceneKind::kStreet ? kitti_preset() : euroc_preset();
    o.frames = 60;
    const Sequence seq(o);
    StereoRenderer r(seq);
    const double bf = o.preset.fx * o.preset.baseline;
    std::vector<double> errors;
    for (std::size_t i : {5u, 40u}) {
      const auto im = r.render(i, true);
      // Rendered depth of both cameras must describe the same surfaces: the right depth at
      // the predicted position equals the left depth (pure x translation).
      cv::Mat gx, gy, mag;
      cv::Sobel(im.left, gx, CV_32F, 1, 0);
      cv::Sobel(im.left, gy, CV_32F, 0, 1);
      cv::magnitude(gx, gy, mag);
      constexpr int kR = 7;
      for (int y = 20; y < im.left.rows - 20; y += 6)
        for (int x = 20; x < im.left.cols - 20; x += 6) {
          const float z = im.left_depth.at<float>(y, x);
          if (z <= 0.3f) continue;
          // Only windows on one smooth surface with texture (corner-free and edge-free).
          cv::Mat win = im.left_depth(cv::Rect(x - kR, y - kR, 2 * kR + 1, 2 * kR + 1));
          double zmin, zmax;
          cv::minMaxLoc(win, &zmin, &zmax);
          if (zmin <= 0 || zmax / zmin > 1.03) continue;
          if (mag.at<float>(y, x) < 40) continue;
          const double d = bf / z;
          const int xr = static_cast<int>(std::lround(x - d));
          if (xr < kR + 4 || xr >= im.right.cols - kR - 4) continue;
          EXPECT_NEAR(im.right_depth.at<float>(y, xr), z, 0.03 * z + 0.02);
          const double m = measure_disparity(im.left, im.right, x, y, d, kR);
          if (!std::isnan(m)) errors.push_back(std::abs(m - d));
        }
    }
    ASSERT_GT(errors.size(), 200u) << to_string(scene);
    const double med = median(errors), p90 = percentile(errors, 0.9);
    std::printf("%s: %zu stereo samples, |disparity - bf/depth| median %.3f px, 90%% %.3f px\n", to_string(scene),
                errors.size(), med, p90);
    EXPECT_LT(med, 0.2) << to_string(scene);
    EXPECT_LT(p90, 0.5) << to_string(scene);
  }
}

// Mean Sobel magnitude along the visible parts of the projected GT segments, for segments
// shifted by `shift` pixels perpendicular to themselves (0: the truth).
double mean_gradient_on_segments(const Sequence& seq, const StereoImages& im, std::size_t i, double shift,
                                 int* samples) {
  cv::Mat gx, gy, mag;
  cv::Sobel(im.left, gx, CV_32F, 1, 0);
  cv::Sobel(im.left, gy, CV_32F, 0, 1);
  cv::magnitude(gx, gy, mag);
  const auto& p = seq.options().preset;
  const Eigen::Isometry3d T_cw = seq.left_pose(i).inverse();
  double sum = 0;
  int n = 0;
  for (const Segment3d& s : seq.scene().edges()) {
    const Eigen::Vector3d a = T_cw * s.a, b = T_cw * s.b;
    const double len = (b - a).norm();
    const int steps = static_cast<int>(len / 0.01);
    for (int k = 1; k < steps; ++k) {
      const Eigen::Vector3d X = a + (b - a) * (double(k) / steps);
      if (X.z() < 0.3) continue;
      const double u = p.fx * X.x() / X.z() + p.cx, v = p.fy * X.y() / X.z() + p.cy;
      // Image direction of the segment for the perpendicular shift.
      const Eigen::Vector3d Y = X + (b - a).normalized() * 0.01;
      if (Y.z() < 0.3) continue;
      Eigen::Vector2d dir(p.fx * Y.x() / Y.z() + p.cx - u, p.fy * Y.y() / Y.z() + p.cy - v);
      if (dir.norm() < 1e-6) continue;
      dir.normalize();
      const double us = u - dir.y() * shift, vs = v + dir.x() * shift;
      const int xi = static_cast<int>(std::lround(us)), yi = static_cast<int>(std::lround(vs));
      if (xi < 2 || yi < 2 || xi >= p.width - 2 || yi >= p.height - 2) continue;
      // Visible: nothing in front of the edge point around its (unshifted) pixel.
      const int xu = static_cast<int>(std::lround(u)), yu = static_cast<int>(std::lround(v));
      if (xu < 2 || yu < 2 || xu >= p.width - 2 || yu >= p.height - 2) continue;
      double zmin;
      cv::minMaxLoc(im.left_depth(cv::Rect(xu - 1, yu - 1, 3, 3)), &zmin, nullptr);
      if (zmin < X.z() * 0.97) continue;
      sum += mag.at<float>(yi, xi);
      ++n;
    }
  }
  *samples = n;
  return n > 0 ? sum / n : 0;
}

TEST(SynthGeometry, ProjectedSegmentsLandOnEdges) {
  for (SceneKind scene : {SceneKind::kOffice, SceneKind::kCorridor, SceneKind::kStreet}) {
    SequenceOptions o;
    o.scene = scene;
    o.preset = scene == SceneKind::kStreet ? kitti_preset() : euroc_preset();
    o.frames = 100;
    const Sequence seq(o);
    StereoRenderer r(seq);
    for (std::size_t i : {10u, 70u}) {
      const auto im = r.render(i, true);
      cv::Mat gx, gy, mag;
      cv::Sobel(im.left, gx, CV_32F, 1, 0);
      cv::Sobel(im.left, gy, CV_32F, 0, 1);
      cv::magnitude(gx, gy, mag);
      const double background = cv::mean(mag)[0];
      int n0 = 0, n5 = 0;
      const double on = mean_gradient_on_segments(seq, im, i, 0.0, &n0);
      const double off = mean_gradient_on_segments(seq, im, i, 5.0, &n5);
      std::printf("%s frame %zu: gradient on GT segments %.1f (%d samples), 5 px off %.1f, image mean %.1f, ratio %.1f\n",
                  to_string(scene), i, on, n0, off, background, on / background);
      EXPECT_GT(n0, 300);
      EXPECT_GT(on, 3.0 * background) << to_string(scene) << " frame " << i;
      EXPECT_GT(on, 2.0 * off) << to_string(scene) << " frame " << i;
    }
  }
}

TEST(SynthGeometry, TrajectoriesArePlausibleAndLoopsClose) {
  struct Case {
    SceneKind scene;
    CameraPreset preset;
    int frames;
    double max_speed;
  };
  for (const Case& c : {Case{SceneKind::kOffice, euroc_preset(), 460, 1.5}, Case{SceneKind::kCorridor, euroc_preset(), 800, 1.5},
                        Case{SceneKind::kStreet, kitti_preset(), 200, 15.0}}) {
    SequenceOptions o;
    o.scene = c.scene;
    o.preset = c.preset;
    o.frames = c.frames;
    o.loop = true;
    const Sequence seq(o);
    // Differentiate the continuous trajectory finely: speed and angular rate limits.
    const double T = (c.frames - 1) / c.preset.fps, dt = 0.005;
    double vmax = 0, wmax = 0, travelled = 0;
    for (double t = 0; t + dt <= T; t += dt) {
      const Eigen::Isometry3d a = seq.path().pose(t), b = seq.path().pose(t + dt);
      const double step = (b.translation() - a.translation()).norm();
      travelled += step;
      vmax = std::max(vmax, step / dt);
      wmax = std::max(wmax, Eigen::AngleAxisd(a.rotation().transpose() * b.rotation()).angle() / dt);
    }
    const double wlimit = 90.0 * M_PI / 180.0;
    std::printf("%s loop: %.1f m, max speed %.2f m/s, max angular rate %.1f deg/s\n", to_string(c.scene), travelled,
                vmax, wmax * 180 / M_PI);
    EXPECT_LE(vmax, c.max_speed);
    EXPECT_LE(wmax, wlimit);
    EXPECT_GE(travelled, 30.0);
    EXPECT_GE(seq.path().length(), 30.0);  // the loop itself, without the walking sway
    // The path returns to its start area.
    const Eigen::Isometry3d first = seq.left_pose(0), last = seq.left_pose(seq.size() - 1);
    EXPECT_LT((first.translation() - last.translation()).norm(), 0.1 * travelled / 3.0);
    double min_return = 1e9;
    for (std::size_t i = seq.size() * 3 / 4; i < seq.size(); ++i)
      min_return = std::min(min_return, (seq.left_pose(i).translation() - first.translation()).norm());
    EXPECT_LT(min_return, c.max_speed > 2 ? 3.0 : 0.5);
  }
}

// --loop-overlap: after the return the camera travels that share of the path again, along the
// first lap (a longer revisit, for loop-closing tests).
TEST(SynthGeometry, LoopOverlapIsTravelledAgainAlongTheFirstLap) {
  SequenceOptions o;
  o.loop = true;
  o.frames = 540;
  o.loop_overlap = 0.15;
  const Sequence seq(o);
  const double T = (o.frames - 1) / o.preset.fps;
  EXPECT_NEAR(seq.path().speed() * T, 1.15 * seq.path().length(), 1e-6);
  // The last frame is where the first lap was after 15 % of the path (frame ~70), far from the start.
  const Eigen::Vector3d last = seq.left_pose(seq.size() - 1).translation();
  double nearest = 1e9;
  std::size_t at = 0;
  for (std::size_t i = 0; i < seq.size() / 2; ++i) {
    const double d = (seq.left_pose(i).translation() - last).norm();
    if (d < nearest) nearest = d, at = i;
  }
  EXPECT_LT(nearest, 0.1);
  EXPECT_NEAR(static_cast<double>(at), 0.15 / 1.15 * (o.frames - 1), 5);
  EXPECT_GT((seq.left_pose(0).translation() - last).norm(), 3.0);
  o.loop_overlap = 1.5;
  EXPECT_THROW(Sequence{o}, InputError);
  o.loop_overlap = 0.15;
  o.frames = 480;  // 1.15 x 31 m in 24 s is faster than the office walk allows
  EXPECT_THROW(Sequence{o}, InputError);
}

TEST(SynthGeometry, ExposureVariesWithinTwentyPercent) {
  SequenceOptions o;
  const Sequence seq(o);
  double lo = 10, hi = 0;
  for (double t = 0; t < 60; t += 0.05) {
    lo = std::min(lo, seq.sensor().exposure(t));
    hi = std::max(hi, seq.sensor().exposure(t));
  }
  EXPECT_GE(lo, 0.8);
  EXPECT_LE(hi, 1.2);
  EXPECT_LT(lo, 0.9);  // it really changes
  EXPECT_GT(hi, 1.1);
}

TEST(SynthGeometry, MotionBlurFollowsTheMotion) {
  // Blurred frames lose high-frequency energy compared with sharp ones of the same pose.
  SequenceOptions o;
  o.scene = SceneKind::kStreet;
  o.preset = kitti_preset();
  o.frames = 20;
  const Sequence sharp_seq(o);
  o.motion_blur = true;
  const Sequence blur_seq(o);
  StereoRenderer rs(sharp_seq), rb(blur_seq);
  const auto a = rs.render(10), b = rb.render(10);
  cv::Mat la, lb;
  cv::Laplacian(a.left, la, CV_32F);
  cv::Laplacian(b.left, lb, CV_32F);
  const double ea = cv::norm(la), eb = cv::norm(lb);
  EXPECT_LT(eb, 0.95 * ea);
  EXPECT_NEAR(cv::mean(a.left)[0], cv::mean(b.left)[0], 3.0);  // same exposure, same scene
}

}  // namespace
}  // namespace plslam::synth
