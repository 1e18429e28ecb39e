#pragma once
// A map line projected into an image, and which of the image's detected lines it is: nearly
// parallel, both projected endpoints close to the detected line, overlapping it, and nearest in
// LBD distance. Tracking matches map lines to frames with it, loop closing fuses lines across a
// loop with it.
#include <functional>
#include <optional>

#include <Eigen/Core>
#include <opencv2/core.hpp>

#include "plslam/geometry/se3.h"
#include "plslam/geometry/stereo_camera.h"
#include "plslam/map/frame_data.h"
#include "plslam/map/map_line.h"

namespace plslam::map {

struct ProjectedSegment {
  Eigen::Vector2d start, end;  // left-image pixels
};

struct LineMatchGate {
  double radius = 6.0;         // pixels: both projected endpoints to the detected line
  double max_angle_deg = 10;
  double min_overlap = 0.3;    // of the projected segment's length
};

// Nullopt when an endpoint is behind the camera (z <= 5 cm), both lie outside the image, or the
// projection is shorter than 10 px (too short to match by direction).
std::optional<ProjectedSegment> project_line(const geometry::StereoCamera& cam, const geometry::SE3& T_cw,
                                             const MapLine& line);

// The index of the best detected line of `d` for `p` with descriptor `desc`, or -1; lines for
// which skip(j) holds are left out. *distance receives its LBD distance.
int best_line_match(const FrameData& d, const ProjectedSegment& p, const cv::Mat& desc, const LineMatchGate& gate,
                    const std::function<bool(std::size_t)>& skip, int* distance);

}  // namespace plslam::map
