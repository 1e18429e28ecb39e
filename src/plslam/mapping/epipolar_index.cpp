#include "plslam/mapping/epipolar_index.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <numbers>

namespace plslam::mapping {
namespace {
constexpr double kInnerRadius = 16.0;  // px: points this close to the epipole are always returned
constexpr double kRingRatio = 2.0;     // outer / inner radius: the angular window overshoots by at most this
constexpr int kMaxRings = 80;          // 16 * 2^79 px: beyond any finite epipole in doubles
constexpr double kPi = std::numbers::pi;
}  // namespace

int EpipolarIndex::ring_of(double rho) {
  if (rho < kInnerRadius) return 0;
  // ring k >= 1 holds rho in [r0 q^(k-1), r0 q^k), q = kRingRatio
  const int k = 1 + static_cast<int>(std::floor(std::log(rho / kInnerRadius) / std::log(kRingRatio)));
  return std::min(k, kMaxRings - 1);
}

EpipolarIndex::EpipolarIndex(const std::vector<Eigen::Vector2d>& points, const Eigen::Vector3d& epipole, double band)
    : epipole_h_(epipole), band_(band), size_(static_cast<int>(points.size())) {
  const double w = epipole.z(), scale = epipole.head<2>().norm();
  // An epipole further than ~1e15 px is numerically at infinity: directions from it are all equal.
  finite_ = std::isfinite(w) && std::isfinite(scale) && std::abs(w) > 1e-15 * scale;
  if (!finite_) return;
  epipole_ = epipole.head<2>() / w;
  rings_.resize(kMaxRings);
  inner_.assign(kMaxRings, 0.0);
  for (int k = 1; k < kMaxRings; ++k) inner_[static_cast<std::size_t>(k)] = kInnerRadius * std::pow(kRingRatio, k - 1);
  // A point at distance rho >= inner within `band` of the half-line deviates in angle by at most
  // asin(band / rho); a small margin covers the rounding of the stored angles. From half the
  // inner radius on (asin(1/2) = 30 deg) the whole ring is read.
  window_.assign(kMaxRings, -1.0);
  for (std::size_t k = 0; k < window_.size(); ++k)
    if (band < 0.5 * inner_[k]) window_[k] = std::asin(band / inner_[k]) + 1e-12;
  for (int i = 0; i < size_; ++i) {
    const Eigen::Vector2d d = points[static_cast<std::size_t>(i)] - epipole_;
    rings_[static_cast<std::size_t>(ring_of(d.norm()))].push_back({std::atan2(d.y(), d.x()), i});
  }
  for (auto& ring : rings_) {
    std::sort(ring.begin(), ring.end(), [](const Entry& a, const Entry& b) { return a.angle < b.angle; });
  }
}

bool EpipolarIndex::ray(const Eigen::Vector3d& v, Ray* out) const {
  if (!finite_) return false;
  // x(z) - e2 = z (v_xy e_w - e_xy v_w) / (e_w (z v_w + e_w)), and z v_w + e_w > 0 wherever the
  // point is in front of camera 2, so the direction keeps the sign of (v_xy e_w - e_xy v_w) / e_w.
  const double ew = epipole_h_.z();
  const Eigen::Vector2d d = (v.head<2>() * ew - epipole_h_.head<2>() * v.z()) / ew;
  const double n = d.norm();
  if (!(n > 0) || !std::isfinite(n)) return false;  // the ray runs along the baseline
  out->direction = d / n;
  out->angle = std::atan2(out->direction.y(), out->direction.x());
  // |x(z) - e2| = z |d| / (z v_w + e_w): with e_w, v_w > 0 it grows from 0 towards |d| / v_w, the
  // distance to the vanishing point; otherwise it is unbounded.
  out->length = std::numeric_limits<double>::infinity();
  if (ew > 0 && v.z() > 0) out->length = n / v.z();
  // Camera 1 behind camera 2 (e_w < 0, forward motion): only depths with z v_w + e_w > 0 are in
  // front of camera 2, and their distance falls from infinity to |d| / v_w as z grows, so the
  // segment runs outwards from the vanishing point; with v_w <= 0 no depth is in front.
  out->start = 0.0;
  if (ew < 0) out->start = v.z() > 0 ? n / v.z() : std::numeric_limits<double>::infinity();
  return true;
}

void EpipolarIndex::query_all(std::vector<int>* out) const {
  out->resize(static_cast<std::size_t>(size_));
  for (int i = 0; i < size_; ++i) (*out)[static_cast<std::size_t>(i)] = i;
}

void EpipolarIndex::query(const Ray& ray, std::vector<int>* out) const {
  out->clear();
  if (!finite_) {
    query_all(out);
    return;
  }
  const double theta = ray.angle;
  for (std::size_t k = 0; k < rings_.size(); ++k) {
    if (inner_[k] > ray.length + band_) break;  // beyond the vanishing point
    if (k + 1 < inner_.size() && inner_[k + 1] < ray.start - band_) continue;  // before the segment
    const auto& ring = rings_[k];
    if (ring.empty()) continue;
    const double window = window_[k];
    if (window < 0) {  // wide window: the whole ring
      for (const auto& e : ring) out->push_back(e.index);
      continue;
    }
    auto read = [&](double lo, double hi) {  // angles in [lo, hi], within (-pi, pi]
      auto it = std::lower_bound(ring.begin(), ring.end(), lo, [](const Entry& e, double a) { return e.angle < a; });
      for (; it != ring.end() && it->angle <= hi; ++it) out->push_back(it->index);
    };
    const double lo = theta - window, hi = theta + window;
    if (lo < -kPi) {  // windows wrapping around +-pi are read in two parts
      read(-kPi, hi);
      read(lo + 2 * kPi, kPi);
    } else if (hi > kPi) {
      read(lo, kPi);
      read(-kPi, hi - 2 * kPi);
    } else {
      read(lo, hi);
    }
  }
}

}  // namespace plslam::mapping
