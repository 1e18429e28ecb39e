#pragma once
// A 2D line segment in full-resolution pixel coordinates (pixel centres at integers) and its
// Hough parameters about the image centre, which the merger uses to group broken pieces.
#include <cmath>
#include <vector>

#include <opencv2/core.hpp>

namespace plslam::features {

struct LineSegment {
  cv::Point2f start, end;  // oriented: the brighter side lies to the right of start->end
  float response = 0;      // length in pixels after merging; detectors set their own score
  int fragments = 1;       // how many detected pieces were merged into this segment

  float length() const { return static_cast<float>(cv::norm(end - start)); }
  cv::Point2f direction() const {  // unit vector start->end
    const float n = length();
    return n > 0 ? (end - start) / n : cv::Point2f(1, 0);
  }
  // Angle of start->end in radians, in (-pi, pi].
  float angle() const { return std::atan2(end.y - start.y, end.x - start.x); }
};

// Hough form: points p on the infinite line satisfy n(theta) . (p - centre) = rho with
// n = (cos theta, sin theta) and theta in [0, pi). rho is signed.
struct HoughLine {
  double rho = 0;
  double theta = 0;
};

HoughLine to_hough(const LineSegment& s, const cv::Point2f& centre);

// Smallest difference between two Hough angles, accounting for the wrap at pi (radians).
double hough_angle_difference(double theta_a, double theta_b);

// Perpendicular distance from p to the infinite line through s.
double distance_to_line(const LineSegment& s, const cv::Point2f& p);

}  // namespace plslam::features
