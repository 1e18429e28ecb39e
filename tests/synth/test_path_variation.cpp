// `synth --path-seed`: another path through the same scene, for localization on unseen images.
#include <gtest/gtest.h>

#include <cmath>

#include "plslam/synth/sequence.h"

namespace plslam::synth {
namespace {

SequenceOptions office(std::uint64_t path_seed) {
  SequenceOptions o;
  o.scene = SceneKind::kOffice;
  o.frames = 480;
  o.loop = true;
  o.seed = 1;
  o.path_seed = path_seed;
  return o;
}

TEST(PathVariation, ZeroIsTheScenesOwnPath) {
  const auto v = path_variation(0, false);
  EXPECT_EQ(v.start, 0);
  EXPECT_FALSE(v.reverse);
  EXPECT_EQ(v.lateral, 0);
  EXPECT_EQ(v.height, 0);
  const Sequence a(office(0));
  SequenceOptions o = office(0);
  const Sequence b(o);
  EXPECT_TRUE(a.left_pose(100).matrix() == b.left_pose(100).matrix());
}

TEST(PathVariation, SeedsDrawBoundedDeterministicVariations) {
  int reversed = 0;
  for (std::uint64_t s = 1; s <= 40; ++s) {
    for (bool vehicle : {false, true}) {
      const auto v = path_variation(s, vehicle);
      const auto w = path_variation(s, vehicle);
      EXPECT_EQ(v.start, w.start);
      EXPECT_GE(v.start, 0);
      EXPECT_LT(v.start, 1);
      EXPECT_LE(std::abs(v.lateral), vehicle ? 0.5 : 0.25);
      EXPECT_LE(std::abs(v.height), vehicle ? 0.05 : 0.1);
      reversed += v.reverse;
    }
  }
  EXPECT_GT(reversed, 10);  // both directions occur
  EXPECT_LT(reversed, 70);
}

// Same scene (the scene seed is unchanged), another trajectory: the path's points are the
// scene's path moved by the variation, and the camera still moves smoothly.
TEST(PathVariation, AnotherPathThroughTheSameScene) {
  const Sequence base(office(0)), other(office(2));
  EXPECT_EQ(base.scene().path, other.scene().path);
  EXPECT_NEAR(base.path().length(), other.path().length(), 1e-9);
  const auto v = path_variation(2, false);
  double far = 0;
  for (std::size_t i = 0; i < 480; i += 40) {
    far = std::max(far, (base.left_pose(i).translation() - other.left_pose(i).translation()).norm());
  }
  EXPECT_GT(far, 1.0);
  // Every pose of the varied path lies within sway + offset of the scene's path.
  for (std::size_t i = 0; i < 480; i += 7) {
    const Eigen::Vector3d p = other.left_pose(i).translation();
    double nearest = 1e9;
    for (std::size_t j = 0; j < 2000; ++j) {
      const Eigen::Vector3d q = base.path().pose(j * base.path().length() / base.path().speed() / 2000).translation();
      nearest = std::min(nearest, (p.head<2>() - q.head<2>()).norm());
    }
    EXPECT_LT(nearest, std::abs(v.lateral) + 0.12) << i;
  }
  for (std::size_t i = 1; i < 480; ++i) {
    const double step = (other.left_pose(i).translation() - other.left_pose(i - 1).translation()).norm();
    EXPECT_LT(step, 0.15) << i;  // ~1.3 m/s at 20 Hz, plus sway
  }
}

}  // namespace
}  // namespace plslam::synth
