#include "plslam/features/ssc.h"

#include <algorithm>
#include <array>
#include <stdexcept>
#include <cmath>
#include <numeric>

namespace plslam::features {

// Derivation of the width bounds (the paper's equations 1-2 model the packing differently and
// contain typos; these follow from the covering actually implemented below).
//
// The covering uses square cells of side c = w/2. A kept point in cell (i, j) covers cells
// [i-2, i+2] x [j-2, j+2]. A later candidate survives only if its cell is at least 3 cells away
// in x or in y, i.e. more than 2c = w pixels away in that axis: kept points are pairwise more
// than w apart in the max-norm.
//
// Upper bound. Tile the W x H image with half-open boxes of side w: one box can hold at most
// one kept point, and there are ceil(W/w) * ceil(H/w) <= (W/w + 1)(H/w + 1) boxes. Keeping N
// points therefore needs (W + w)(H + w) >= N w^2, i.e. (N-1) w^2 - (W+H) w - W H <= 0, whose
// positive root is
//     w_high = ( (W+H) + sqrt((W+H)^2 + 4 (N-1) W H) ) / (2 (N-1)).
// No input can give N points above w_high.
//
// Lower bound. A kept point covers 5 cells per axis, an interval of length 5c = 2.5 w holding at
// most 2.5 w + 1 integer coordinates, so it removes at most (2.5 w + 1)^2 candidates at distinct
// integer pixels (FAST corners of one level are). The greedy pass ends with every candidate kept
// or covered, so K candidates leave at least K / (2.5 w + 1)^2 points, which is >= N when
//     w <= w_low = (sqrt(K/N) - 1) / 2.5.
// Widths under one pixel would make the grid larger than the image, so w_low is clamped to 1.
SscBounds ssc_width_bounds(int candidates, int target, cv::Size size) {
  const double W = size.width, H = size.height;
  const double N = std::max(1, target);
  SscBounds b;
  b.high = N <= 1 ? std::max(W, H) + 1.0
                  : ((W + H) + std::sqrt((W + H) * (W + H) + 4.0 * (N - 1.0) * W * H)) / (2.0 * (N - 1.0));
  const double ratio = static_cast<double>(std::max(candidates, 1)) / N;
  b.low = std::max(1.0, (std::sqrt(ratio) - 1.0) / 2.5);
  b.high = std::max(b.high, b.low);
  return b;
}

std::vector<int> order_by_response(const std::vector<cv::KeyPoint>& keypoints) {
  const int n = static_cast<int>(keypoints.size());
  std::vector<int> order(static_cast<std::size_t>(n));
  constexpr int kBins = 1024;
  const bool small_integers = std::all_of(keypoints.begin(), keypoints.end(), [](const cv::KeyPoint& k) {
    return k.response >= 0.f && k.response < kBins && static_cast<float>(static_cast<int>(k.response)) == k.response;
  });
  if (small_integers) {
    // Counting sort, descending, stable: O(K) instead of O(K log K).
    std::vector<int> start(kBins + 1, 0);
    for (const auto& k : keypoints) ++start[static_cast<std::size_t>(kBins - 1 - static_cast<int>(k.response)) + 1];
    for (int i = 0; i < kBins; ++i) start[static_cast<std::size_t>(i) + 1] += start[static_cast<std::size_t>(i)];
    for (int i = 0; i < n; ++i) {
      const int bin = kBins - 1 - static_cast<int>(keypoints[static_cast<std::size_t>(i)].response);
      order[static_cast<std::size_t>(start[static_cast<std::size_t>(bin)]++)] = i;
    }
    return order;
  }
  std::iota(order.begin(), order.end(), 0);
  std::stable_sort(order.begin(), order.end(), [&](int a, int b) {
    return keypoints[static_cast<std::size_t>(a)].response > keypoints[static_cast<std::size_t>(b)].response;
  });
  return order;
}

namespace {

// Candidates in visiting order (strongest first): original index and integer pixel position
// packed as y << 16 | x. The covering works on whole pixels (FAST corners are whole pixels).
struct SortedCandidates {
  std::vector<int> index;
  std::vector<uint32_t> packed;
};

SortedCandidates sort_candidates(const std::vector<cv::KeyPoint>& keypoints, cv::Size size) {
  const int k = static_cast<int>(keypoints.size());
  SortedCandidates s;
  s.index.resize(static_cast<std::size_t>(k));
  s.packed.resize(static_cast<std::size_t>(k));
  auto pack = [&](const cv::KeyPoint& kp) {
    const auto x = static_cast<uint32_t>(std::clamp(static_cast<int>(kp.pt.x), 0, size.width - 1));
    const auto y = static_cast<uint32_t>(std::clamp(static_cast<int>(kp.pt.y), 0, size.height - 1));
    return y << 16 | x;
  };
  // Counting sort on integer scores (FAST's), descending and stable, in two sequential passes.
  constexpr int kBins = 256;  // FAST scores are below 256
  std::array<int, kBins + 1> start{};
  bool integer_scores = true;
  for (const auto& kp : keypoints) {
    const float r = kp.response;
    // Integer test by conversion: std::floor is a library call without SSE4.1.
    if (!(r >= 0.f && r < kBins && static_cast<float>(static_cast<int>(r)) == r)) {
      integer_scores = false;
      break;
    }
    ++start[static_cast<std::size_t>(kBins - static_cast<int>(r))];
  }
  if (integer_scores) {
    for (int i = 0; i < kBins; ++i) start[static_cast<std::size_t>(i) + 1] += start[static_cast<std::size_t>(i)];
    for (int i = 0; i < k; ++i) {
      const auto& kp = keypoints[static_cast<std::size_t>(i)];
      const auto pos = static_cast<std::size_t>(start[static_cast<std::size_t>(kBins - 1 - static_cast<int>(kp.response))]++);
      s.index[pos] = i;
      s.packed[pos] = pack(kp);
    }
    return s;
  }
  s.index = order_by_response(keypoints);
  for (int i = 0; i < k; ++i) s.packed[static_cast<std::size_t>(i)] = pack(keypoints[static_cast<std::size_t>(s.index[static_cast<std::size_t>(i)])]);
  return s;
}

// One greedy covering pass at width w over the sorted candidates. Stops once `limit` points are
// kept (the caller then only needs to know it overshot). Returns the kept count.
class Coverer {
 public:
  Coverer(const std::vector<uint32_t>& packed, cv::Size size) : packed_(packed), size_(size) {}

  int run(int w, int limit, std::vector<int>& kept_sorted_pos) {
    // Cells of side c = w/2: the cell of pixel x is floor(2x / w).
    const int cols = (2 * (size_.width - 1)) / w + 1;
    const int rows = (2 * (size_.height - 1)) / w + 1;
    // Two margin cells on each side so covering a 5x5 block needs no bounds checks.
    const int stride = cols + 4;
    grid_.assign(static_cast<std::size_t>(stride) * static_cast<std::size_t>(rows + 4), 0);
    // Pixel -> cell lookups, filled incrementally (no division per pixel); the pass then needs no
    // division or float conversion.
    fill_cells(col_of_x_, size_.width, w, 1);
    fill_cells(row_of_y_, size_.height, w, stride);
    kept_sorted_pos.clear();
    const int n = static_cast<int>(packed_.size());
    uint8_t* g = grid_.data();
    const uint32_t* p = packed_.data();
    const int* cx = col_of_x_.data();
    const int* ry = row_of_y_.data();
    for (int i = 0; i < n; ++i) {
      uint8_t* cell = g + ry[p[i] >> 16] + cx[p[i] & 0xFFFFu];
      if (*cell) continue;
      kept_sorted_pos.push_back(i);
      if (static_cast<int>(kept_sorted_pos.size()) >= limit) break;
      for (int dy = -2; dy <= 2; ++dy) {
        uint8_t* row = cell + dy * stride;
        row[-2] = row[-1] = row[0] = row[1] = row[2] = 1;
      }
    }
    return static_cast<int>(kept_sorted_pos.size());
  }

 private:
  // table[x] = (floor(2x / w) + 2) * scale for x in [0, n).
  static void fill_cells(std::vector<int>& table, int n, int w, int scale) {
    table.resize(static_cast<std::size_t>(n));
    int q = 0, r = 0;  // 2x = q w + r, 0 <= r < w
    for (int x = 0; x < n; ++x) {
      table[static_cast<std::size_t>(x)] = (q + 2) * scale;
      r += 2;
      while (r >= w) {
        r -= w;
        ++q;
      }
    }
  }

  const std::vector<uint32_t>& packed_;
  cv::Size size_;
  std::vector<uint8_t> grid_;
  std::vector<int> col_of_x_, row_of_y_;
};

}  // namespace

SscResult ssc_select(const std::vector<cv::KeyPoint>& keypoints, int target, cv::Size size,
                     double tolerance_fraction, double width_hint) {
  SscResult result;
  const int k = static_cast<int>(keypoints.size());
  if (target <= 0 || k == 0 || size.width < 1 || size.height < 1) return result;
  if (size.width > 65535 || size.height > 65535) throw std::invalid_argument("ssc_select: image too large");
  if (k <= target) {
    result.kept = order_by_response(keypoints);
    return result;
  }
  const SortedCandidates sorted = sort_candidates(keypoints, size);
  const int tolerance = static_cast<int>(std::floor(tolerance_fraction * target));
  const SscBounds bounds = ssc_width_bounds(k, target, size);

  Coverer cover(sorted.packed, size);
  std::vector<int> pass, best;
  pass.reserve(static_cast<std::size_t>(target + tolerance + 1));
  best.reserve(static_cast<std::size_t>(target + tolerance + 1));
  double best_width = 0;
  // Integer widths, as in Bailo et al.: the count changes in steps anyway, and the search
  // ends after about log2(w_high) passes.
  int low = static_cast<int>(std::floor(bounds.low));
  int high = static_cast<int>(std::ceil(bounds.high));
  bool done = false;
  // One probe: true when the search is over (count within tolerance).
  auto probe = [&](int w) {
    const int count = cover.run(w, target + tolerance + 1, pass);
    ++result.iterations;
    if (std::abs(count - target) <= tolerance) {
      best.swap(pass);
      best_width = w;
      return true;
    }
    if (count > target) {
      best.swap(pass);  // feasible: remember it, then try wider
      best_width = w;
      low = std::max(low, w + 1);
    } else {
      high = std::min(high, w - 1);
    }
    return false;
  };
  const int hint = static_cast<int>(std::lround(width_hint));
  if (hint >= low && hint <= high) {
    done = probe(hint);
    // Feasible at the hint: the next width decides whether the hint was the widest.
    if (!done && low == hint + 1 && low <= high) done = probe(hint + 1);
    // Infeasible at the hint: try just below it.
    else if (!done && high == hint - 1 && low <= high) done = probe(hint - 1);
  }
  while (!done && low <= high) done = probe(low + (high - low) / 2);
  if (!done && best.empty()) {
    // Only possible with duplicate positions: fall back to the narrowest cover.
    const int w = std::max(1, static_cast<int>(std::floor(bounds.low)));
    best_width = w;
    cover.run(w, target, best);
    ++result.iterations;
  }
  if (static_cast<int>(best.size()) > target + tolerance) best.resize(static_cast<std::size_t>(target));
  result.width = best_width;
  result.kept.reserve(best.size());
  for (int pos : best) result.kept.push_back(sorted.index[static_cast<std::size_t>(pos)]);
  return result;
}

}  // namespace plslam::features
