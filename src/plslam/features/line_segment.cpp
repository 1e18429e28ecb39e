#include "plslam/features/line_segment.h"

namespace plslam::features {

HoughLine to_hough(const LineSegment& s, const cv::Point2f& centre) {
  const cv::Point2d d = s.end - s.start;
  double theta = std::atan2(d.y, d.x) + CV_PI / 2;  // normal direction
  theta = std::fmod(theta, CV_PI);
  if (theta < 0) theta += CV_PI;
  const cv::Point2d n(std::cos(theta), std::sin(theta));
  const cv::Point2d mid = 0.5 * (cv::Point2d(s.start) + cv::Point2d(s.end)) - cv::Point2d(centre);
  return {n.dot(mid), theta};
}

double hough_angle_difference(double a, double b) {
  double d = std::fabs(a - b);
  d = std::fmod(d, CV_PI);
  return std::min(d, CV_PI - d);
}

double distance_to_line(const LineSegment& s, const cv::Point2f& p) {
  const cv::Point2d d = s.end - s.start;
  const double n = std::sqrt(d.x * d.x + d.y * d.y);
  if (n <= 0) return cv::norm(p - s.start);
  const cv::Point2d v = cv::Point2d(p) - cv::Point2d(s.start);
  return std::fabs(d.x * v.y - d.y * v.x) / n;
}

}  // namespace plslam::features
