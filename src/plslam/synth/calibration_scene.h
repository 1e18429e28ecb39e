#pragma once
// `plslam synth --scene calibration`: a calibration board (calib/board.h) held in front of the
// rig, at the distances, tilts and image positions a careful user sweeps it through, before a
// textured wall. Each frame is an independent view (the board is waved, not walked past), so the
// sequence has no IMU.
#include <cstdint>
#include <vector>

#include <Eigen/Geometry>

#include "plslam/calib/board.h"
#include "plslam/geometry/lens_model.h"
#include "plslam/synth/scene.h"

namespace plslam::synth {

// The board as a textured quad (drawn into the texture with a white margin of one square), a wall
// 1.5 m behind it, and uniform light. The board's first corner is where BoardSpec::corners() puts
// it, in the frame board_pose() gives.
Scene calibration_scene(const calib::BoardSpec& board, std::uint64_t seed);

// The board's frame in the world (T_world_board): x along the board's columns, y along its rows,
// z away from the side with the pattern.
Eigen::Isometry3d board_pose(const calib::BoardSpec& board);

// Left camera poses (T_world_left) for `frames` views: the board's centre at positions spread over
// the whole image (corners included, where distortion is strongest), 0.35 to 0.75 of the image
// width across, tilted up to 50 degrees and turned up to 30 degrees in its plane.
std::vector<Eigen::Isometry3d> calibration_views(const calib::BoardSpec& board, const geometry::LensCamera& lens,
                                                 int frames, std::uint64_t seed);

}  // namespace plslam::synth
