// The rasteriser against hand-computed views: exact depth, occlusion, edge positions and
// anti-aliased coverage.
#include <gtest/gtest.h>

#include "plslam/synth/renderer.h"

namespace plslam::synth {
namespace {

// Camera at the world origin looking along +z (camera frame = world frame).
Scene two_quads() {
  Scene s;
  s.ambient = 1.0;
  const int tex = s.add_texture(make_uniform(0.5f, 0.0f, 1));
  // Front faces point at the camera (u x v along -z).
  s.add_quad({-1, -1, 2}, {0, 2, 0}, {2, 0, 0}, tex);        // x, y in [-1, 1] at z = 2
  s.add_quad({0, -0.5, 1}, {0, 1, 0}, {0.5, 0, 0}, tex);     // x in [0, 0.5], y in [-0.5, 0.5] at z = 1
  s.add_quad({-1, -1, 0.5}, {2, 0, 0}, {0, 2, 0}, tex);      // faces away: culled
  s.background = 0.0f;
  s.bake_lighting();
  return s;
}

TEST(SynthRenderer, DepthOcclusionAndEdges) {
  const Scene scene = two_quads();
  Renderer r(scene, PinholeCamera{400, 300, 100, 100, 200, 150});
  cv::Mat rad, depth;
  r.render(Eigen::Isometry3d::Identity(), rad, &depth);
  // Far quad spans pixels x in [150, 250], y in [100, 200]; near quad x in [200, 250], same rows.
  EXPECT_NEAR(depth.at<float>(150, 180), 2.0f, 1e-5);
  EXPECT_NEAR(depth.at<float>(120, 225), 1.0f, 1e-5);  // near quad wins the z-test
  EXPECT_NEAR(depth.at<float>(120, 199), 2.0f, 1e-5);  // just left of the near quad
  EXPECT_NEAR(depth.at<float>(120, 201), 1.0f, 1e-5);
  EXPECT_EQ(depth.at<float>(150, 100), 0.0f);          // nothing: background
  EXPECT_EQ(depth.at<float>(150, 140), 0.0f);          // the back-facing quad is culled
  EXPECT_EQ(rad.at<float>(150, 100), 0.0f);
  // Shading: the lit value inside, the background outside, half and half on the edge x = 150
  // that runs through pixel centres, a quarter at the corner pixel (x 150, y 100), which 1 of
  // the 4 sub-samples covers.
  const float inside = rad.at<float>(150, 180);
  EXPECT_GT(inside, 0.3f);
  EXPECT_NEAR(rad.at<float>(180, 150), 0.5f * inside, 0.01f * inside);
  EXPECT_NEAR(rad.at<float>(180, 149), 0.0f, 1e-6);
  EXPECT_NEAR(rad.at<float>(180, 151), inside, 0.01f * inside);
  EXPECT_NEAR(rad.at<float>(100, 150), 0.25f * inside, 0.01f * inside);
}

TEST(SynthRenderer, PerspectiveTextureIsExact) {
  // A slanted floor with a 1 m checker texture: the pixel where the texture changes from one
  // square to the next lies where the ray meets x = integer on the plane.
  Scene s;
  s.ambient = 1.0;
  Texture t;
  t.repeat = true;
  t.levels.resize(1);
  t.levels[0].size = 64;
  t.levels[0].texels.resize(64 * 64);
  for (int y = 0; y < 64; ++y)
    for (int x = 0; x < 64; ++x) t.levels[0].texels[y * 64 + x] = ((x / 32 + y / 32) % 2) ? 0.9f : 0.1f;
  build_mips(t);
  const int tex = s.add_texture(std::move(t));
  // Plane y = 1 (below the camera; y down), x in [-4, 4], z in [1, 9]; texture repeats each 2 m,
  // so its colour flips at every integer x and z.
  s.add_quad({-4, 1, 1}, {8, 0, 0}, {0, 0, 8}, tex, 2.0);
  s.background = 0.0f;
  s.bake_lighting();
  Renderer r(s, PinholeCamera{640, 480, 300, 300, 320, 240});
  cv::Mat rad, depth;
  r.render(Eigen::Isometry3d::Identity(), rad, &depth);
  // Row through z = 2.5 (the middle of a square in z): v = 240 + 300 * 1 / 2.5 = 360.
  const int row = 360;
  EXPECT_NEAR(depth.at<float>(row, 320), 2.5f, 1e-4);
  // Along that row, x = 1 m is at u = 320 + 300 * 1 / 2.5 = 440: the colour flips there.
  const float left = rad.at<float>(row, 436), right = rad.at<float>(row, 444);
  EXPECT_GT(std::abs(left - right), 0.3f);
  EXPECT_LT(std::abs(rad.at<float>(row, 430) - left), 0.05f);
  EXPECT_LT(std::abs(rad.at<float>(row, 450) - right), 0.05f);
  // The transition is centred on u = 440 to within a pixel.
  EXPECT_NEAR(rad.at<float>(row, 440), 0.5f * (left + right), 0.25f * std::abs(left - right));
}

}  // namespace
}  // namespace plslam::synth
