#pragma once
// A hand-made map file content with every kind of record (two keyframes with keypoints, lines and
// bags of words, a point and a line seen by both, a covisibility edge, a parent, a loop edge, IMU
// states chained by 0.5 s of IMU samples): the exact-data test of the format, and the fuzz seed
// tests/fuzz/corpus/map_file/tiny_with_imu (tiny_two_keyframes is the version 1 file, without IMU).
#include <memory>

#include "plslam/system/map_file.h"

namespace plslam::test {

inline system::MapContents tiny_map_contents() {
  system::MapContents c;
  auto& m = c.meta;
  m.calib.width = 64;
  m.calib.height = 48;
  m.calib.fx = m.calib.fy = 50;
  m.calib.cx = 31.5;
  m.calib.cy = 23.5;
  m.calib.baseline = 0.1;
  m.vocabulary_checksum = 0x1234;
  m.vocabulary_words = 10;
  m.vocabulary_nodes = 11;
  m.next_ids = {2, 5, 3};
  m.T_gt_map = geometry::SE3(Eigen::Quaterniond(0.9, 0.1, 0.2, 0.3), Eigen::Vector3d(1, 2, 3));
  m.created_by = "test";
  m.config = "{}";
  for (long id : {0L, 1L}) {
    auto d = std::make_shared<map::FrameData>();
    d->calib = m.calib;
    d->frame_id = 10 * id;
    d->timestamp = 0.5 * static_cast<double>(id);
    for (int i = 0; i < 3; ++i) {
      d->keypoints.emplace_back(10.f + 5 * i, 20.f + i, 31.f, 45.f * i, 0.5f, i % 2, -1);
      d->u_right.push_back(i == 2 ? -1.f : 5.f + i);
      d->depth.push_back(i == 2 ? -1.f : 1.5f + i);
    }
    d->descriptors = cv::Mat(3, 32, CV_8U, cv::Scalar(static_cast<int>(id) + 7));
    map::LineObservation l;
    l.segment.start = {1, 2};
    l.segment.end = {30, 40};
    l.segment.response = 50;
    l.left_line = Eigen::Vector3d(0.6, 0.8, -5);
    l.right_line = Eigen::Vector3d(0.6, 0.8, -4);
    l.stereo = true;
    l.start_cam = Eigen::Vector3d(-0.5, 0.1, 2);
    l.end_cam = Eigen::Vector3d(0.5, 0.3, 2.5);
    d->lines.push_back(l);
    d->line_descriptors = cv::Mat(1, 32, CV_8U, cv::Scalar(3));
    d->build_grid();
    system::SavedKeyframe k;
    k.id = id;
    k.data = d;
    k.T_cw = geometry::SE3(Eigen::Matrix3d::Identity(), Eigen::Vector3d(0, 0, -0.3 * static_cast<double>(id)));
    auto place = std::make_shared<place::PlaceDescription>();
    place->bow = {{1, 0.25}, {4, 0.75}};
    place->features = {{0, {0, 2}}, {3, {1}}};
    k.place = place;
    k.parent = id == 1 ? 0 : -1;
    k.covisibility = {{1 - id, 2}};
    k.loop_edges = {1 - id};
    system::SavedImuState imu;
    imu.v = Eigen::Vector3d(0.2, -0.1, 0.05 * static_cast<double>(id));
    imu.bias.gyro = Eigen::Vector3d(1e-3, -2e-3, 3e-3);
    imu.bias.acc = Eigen::Vector3d(0.02, 0.01, -0.03);
    imu.estimated = id == 0;
    if (id == 1) {
      std::vector<ImuSample> samples;
      for (int i = 0; i <= 5; ++i) samples.push_back({0.1 * i, Eigen::Vector3d(0.1, 0.02 * i, -0.05), Eigen::Vector3d(0.3, -0.2 * i, 9.81)});
      imu.previous = 0;
      imu.from_previous = std::make_shared<const inertial::Preintegration>(samples, 0.0, 0.5, imu.bias, kEurocAdis16448Noise);
    }
    k.imu = imu;
    c.keyframes.push_back(k);
  }
  m.gravity_aligned = true;
  system::SavedLandmark p;
  p.id = 3;
  p.created_frame = 0;
  p.reference = 0;
  p.a = Eigen::Vector3d(0.1, 0.2, 1.5);
  p.level0_max_distance = 1.8;
  p.state.normal = Eigen::Vector3d(0, 0, -1);
  p.state.min_distance = 0.3;
  p.state.max_distance = 2.2;
  p.state.descriptor = cv::Mat(1, 32, CV_8U, cv::Scalar(7));
  p.state.visible = 4;
  p.state.found = 3;
  p.observations = {{0, 0}, {1, 1}};
  c.points.push_back(p);
  system::SavedLandmark l = p;
  l.id = 2;
  l.a = Eigen::Vector3d(-0.5, 0.1, 2);
  l.b = Eigen::Vector3d(0.5, 0.3, 2.5);
  l.level0_max_distance = 0;
  l.observations = {{0, 0}, {1, 0}};
  c.lines.push_back(l);
  return c;
}

}  // namespace plslam::test
