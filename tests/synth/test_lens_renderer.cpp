// The lens renderer against the pinhole rasteriser: a fisheye's pixel shows what the pinhole view
// shows along the same ray, at the same depth, over every cube face the lens needs.
#include <algorithm>
#include <vector>

#include <gtest/gtest.h>

#include "plslam/core/error.h"
#include "plslam/synth/lens_renderer.h"
#include "plslam/synth/sequence.h"

namespace plslam::synth {
namespace {

// A 150-degree TUM-VI-like fisheye (its corners look 75 degrees aside), rendered from faces, and
// an undistorted pinhole of 90 degrees at the same pose, rendered directly.
TEST(LensRenderer, FisheyePixelsShowWhatThePinholeSeesAlongTheirRays) {
  const Scene scene = build_scene(SceneKind::kOffice, 3);
  const geometry::LensCamera fisheye{geometry::LensModel::kEquidistant, 376, 240, 170.0, 170.0, 187.5, 119.5,
                                     {0.0034823894, 0.00071520687, -0.0020532361, 0.00020293673}};
  const geometry::LensCamera pinhole{geometry::LensModel::kRadialTangential, 600, 600, 300.0, 300.0, 299.5, 299.5, {}};
  LensRenderer lens_renderer(scene, fisheye);
  LensRenderer pinhole_renderer(scene, pinhole);
  EXPECT_GE(lens_renderer.faces(), 3);  // front and both sides at least
  EXPECT_EQ(pinhole_renderer.faces(), 0);  // rendered directly
  const SequenceOptions o;
  const Sequence seq(o);
  int compared = 0;
  for (std::size_t frame : {0, 60, 150}) {
    const Eigen::Isometry3d T_wc = seq.left_pose(frame);
    cv::Mat lr, ld, pr, pd;
    lens_renderer.render(T_wc, lr, &ld);
    pinhole_renderer.render(T_wc, pr, &pd);
    ASSERT_EQ(lr.size(), cv::Size(376, 240));
    std::vector<double> depth_error, radiance_error;
    for (int y = 0; y < 240; y += 3) {
      for (int x = 0; x < 376; x += 3) {
        const float d = ld.at<float>(y, x);
        if (!(d > 0)) continue;
        const Eigen::Vector3d ray = *fisheye.unproject({x, y});
        const Eigen::Vector3d X = ray * (d / ray.z());
        EXPECT_NEAR(X.z(), d, 1e-4);
        const auto p = pinhole.project(X);
        if (!p || p->x() < 2 || p->y() < 2 || p->x() > 597 || p->y() > 597) continue;
        // The pinhole's depth between its four pixels around p, where they lie on one surface.
        const int u0 = static_cast<int>(p->x()), v0 = static_cast<int>(p->y());
        const float a = static_cast<float>(p->x() - u0), b = static_cast<float>(p->y() - v0);
        const float q[4] = {pd.at<float>(v0, u0), pd.at<float>(v0, u0 + 1), pd.at<float>(v0 + 1, u0),
                            pd.at<float>(v0 + 1, u0 + 1)};
        const auto [lo, hi] = std::minmax({q[0], q[1], q[2], q[3]});
        if (lo > 0 && hi < 1.02f * lo) {
          const float pdepth = (1 - b) * ((1 - a) * q[0] + a * q[1]) + b * ((1 - a) * q[2] + a * q[3]);
          depth_error.push_back(std::abs(pdepth - d) / d);
        }
        cv::Mat patch;
        cv::getRectSubPix(pr, {1, 1}, cv::Point2f(static_cast<float>(p->x()), static_cast<float>(p->y())), patch);
        radiance_error.push_back(std::abs(patch.at<float>(0, 0) - lr.at<float>(y, x)));
      }
    }
    ASSERT_GT(depth_error.size(), 1200u);
    compared += static_cast<int>(depth_error.size());
    // Depth agrees except on occlusion edges, where nearest neighbours pick either side.
    const auto close = std::count_if(depth_error.begin(), depth_error.end(), [](double e) { return e < 0.005; });
    EXPECT_GT(static_cast<double>(close) / depth_error.size(), 0.97) << "frame " << frame;
    std::nth_element(radiance_error.begin(), radiance_error.begin() + radiance_error.size() / 2, radiance_error.end());
    EXPECT_LT(radiance_error[radiance_error.size() / 2], 0.01) << "frame " << frame;  // radiance ~0.1-1
  }
  EXPECT_GT(compared, 5000);
}

// Sequences: the default pinhole rig is the ideal rectified pair; --camera makes a real rig whose
// right camera is turned, and a fisheye of the asked field of view.
TEST(LensRenderer, SequenceCamerasAndFieldOfView) {
  SequenceOptions o;
  o.frames = 2;
  const Sequence ideal(o);
  EXPECT_TRUE(ideal.T_left_right().linear().isIdentity(0));
  EXPECT_EQ(ideal.lens(0).fx, o.preset.fx);
  EXPECT_EQ(ideal.calibration().fx, o.preset.fx);
  o.camera = CameraKind::kEquidistant;
  o.fov_deg = 150;
  const Sequence fisheye(o);
  EXPECT_NEAR(Eigen::AngleAxisd(fisheye.T_left_right().rotation()).angle() * 180 / M_PI, 0.4, 1e-9);
  EXPECT_EQ(fisheye.lens(1).model, geometry::LensModel::kEquidistant);
  const auto l = fisheye.lens(0);  // the field of view from corner to corner
  const double corner_angles = std::acos(l.unproject({0, 0})->z()) + std::acos(l.unproject({l.width - 1.0, l.height - 1.0})->z());
  EXPECT_NEAR(corner_angles * 180 / M_PI, 150, 1.0);
  EXPECT_THROW(fisheye.calibration(), InputError);  // a raw rig has no rectified calibration
  o.camera = CameraKind::kRadialTangential;
  o.fov_deg = 170;
  EXPECT_THROW(Sequence{o}, InputError);
  EXPECT_THROW(parse_camera_kind("omni"), InputError);
  // Rendering: the fisheye's images are of the preset's size and show the scene.
  StereoRenderer renderer(fisheye);
  const auto im = renderer.render(1, true);
  EXPECT_EQ(im.left.size(), cv::Size(o.preset.width, o.preset.height));
  EXPECT_GT(cv::countNonZero(im.right_depth > 0), o.preset.width * o.preset.height * 9 / 10);
}

}  // namespace
}  // namespace plslam::synth
