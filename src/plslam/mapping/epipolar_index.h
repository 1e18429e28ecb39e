#pragma once
// Candidates near an epipolar segment, without testing every keypoint of the other image.
// Triangulation pairs each free keypoint of keyframe 1 with the keypoints of keyframe 2 that lie
// within a band of its epipolar line. Testing all pairs cost O(N1 N2) per keyframe pair (hundreds
// of ms per keyframe on KITTI, so local mapping fell behind tracking and skipped bundle
// adjustment). The projections of a ray of camera 1 (positive depths) into camera 2 fill a
// segment that starts at the epipole e2 and ends at the ray's vanishing point, so a candidate at
// distance rho from e2 must lie within asin(band / rho) of the segment's direction and no further
// than the vanishing point. Points are kept in rings of growing distance from e2, each sorted by
// angle, and a query reads one angular window per ring.
#include <vector>

#include <Eigen/Core>

namespace plslam::mapping {

class EpipolarIndex {
 public:
  // `points`: image-2 positions (pixels); `epipole`: e2 in homogeneous image coordinates (the
  // projection of camera 1's centre into camera 2, K t_21); `band`: the half-width in pixels
  // every query reads around its segment, fixed so each ring's angular window is computed once.
  // With the epipole at infinity (pure sideways motion) queries fall back to returning every point.
  EpipolarIndex(const std::vector<Eigen::Vector2d>& points, const Eigen::Vector3d& epipole, double band);

  // The image-2 segment of the ray whose projection is x(z) = z v + e2 (homogeneous) for depths
  // z > 0: v = K R_21 K^-1 x1 for the keypoint x1 of image 1. Returns false when the ray has no
  // such segment (degenerate geometry: the caller should use query_all).
  struct Ray {
    Eigen::Vector2d direction;  // from the epipole, unit length
    double angle;               // of the direction, in (-pi, pi]
    double length;              // distance from the epipole to the vanishing point (inf: none)
    double start = 0;           // distance from the epipole where points in front of camera 2 begin
  };
  bool ray(const Eigen::Vector3d& v, Ray* out) const;

  // Whether image-2 point `p` lies along the ray's segment, `band` pixels beyond its ends allowed
  // (its distance across is the caller's epipolar test).
  bool along_segment(const Ray& ray, const Eigen::Vector2d& p, double band) const {
    const double t = (p - epipole_).dot(ray.direction);
    return t >= ray.start - band && t <= ray.length + band;
  }

  // Indices (into `points`) of every point within `band` pixels of the ray's segment, and
  // possibly a few more; the caller applies its exact test. No duplicates, in no particular order
  // (callers break ties by index).
  void query(const Ray& ray, std::vector<int>* out) const;
  void query_all(std::vector<int>* out) const;

 private:
  struct Entry {
    double angle;  // direction from the epipole, in (-pi, pi]
    int index;
  };
  static int ring_of(double rho);

  bool finite_ = false;
  Eigen::Vector3d epipole_h_ = Eigen::Vector3d::Zero();
  Eigen::Vector2d epipole_ = Eigen::Vector2d::Zero();
  std::vector<std::vector<Entry>> rings_;  // ring k: rho in [r0 2^(k-1), r0 2^k), ring 0: rho < r0
  std::vector<double> inner_;              // inner radius of each ring
  double band_ = 0;
  std::vector<double> window_;             // each ring's angular half-window for band_ (< 0: whole ring)
  int size_ = 0;
};

}  // namespace plslam::mapping
