#include "plslam/features/quadtree.h"

#include <algorithm>
#include <array>
#include <cmath>

namespace plslam::features {
namespace {

// A node owns the range [begin, end) of a shared index array, so splitting only permutes
// indices instead of copying keypoint lists as ORB-SLAM2 does.
struct Node {
  float x0, y0, x1, y1;
  int begin, end;
  int size() const { return end - begin; }
};

// Point access to the two input layouts. quadrants(xm, ym) gives the child of a point of a node
// split at (xm, ym): 0 top-left, 1 top-right, 2 bottom-left, 3 bottom-right.
struct KeyPointInput {
  const std::vector<cv::KeyPoint>& kps;
  std::size_t size() const { return kps.size(); }
  float response(int i) const { return kps[static_cast<std::size_t>(i)].response; }
  // The initial column of a point: columns of width hx.
  auto columns(float hx, int n) const {
    return [this, hx, n](int i) { return std::clamp(static_cast<int>(kps[static_cast<std::size_t>(i)].pt.x / hx), 0, n - 1); };
  }
  auto quadrants(float xm, float ym) const {
    return [this, xm, ym](int i) {
      const cv::Point2f& p = kps[static_cast<std::size_t>(i)].pt;
      return (p.x < xm ? 0 : 1) + (p.y < ym ? 0 : 2);
    };
  }
};
// Whole-pixel positions: x < xm exactly when x < ceil(xm), and y < ym when the packed y << 16 | x
// is below ceil(ym) << 16, so the split compares integers without converting the points.
struct CornerInput {
  const FastCorners& corners;
  std::size_t size() const { return corners.size(); }
  int response(int i) const { return corners.score[static_cast<std::size_t>(i)]; }
  // As KeyPointInput::columns, by the first whole x of every column (the float formula is
  // monotone in x), so that no point is converted to float.
  auto columns(float hx, int n) const {
    auto column_of = [hx, n](int x) { return std::clamp(static_cast<int>(static_cast<float>(x) / hx), 0, n - 1); };
    std::vector<int> first(static_cast<std::size_t>(std::max(0, n - 1)));
    for (int c = 1; c < n; ++c) {
      int x = std::max(0, static_cast<int>(static_cast<float>(c) * hx) - 2);
      while (column_of(x) < c) ++x;
      while (x > 0 && column_of(x - 1) >= c) --x;
      first[static_cast<std::size_t>(c - 1)] = x;
    }
    return [p = corners.position.data(), first = std::move(first)](int i) {
      const int x = FastCorners::x_of(p[i]);
      int c = 0;
      for (const int f : first) c += x >= f;
      return c;
    };
  }
  auto quadrants(float xm, float ym) const {
    const auto x_split = static_cast<uint32_t>(std::ceil(xm));
    const uint64_t packed_split = static_cast<uint64_t>(std::ceil(ym)) << 16;
    return [p = corners.position.data(), x_split, packed_split](int i) {
      const uint32_t v = p[i];
      return static_cast<int>((v & 0xFFFFu) >= x_split) + 2 * static_cast<int>(v >= packed_split);
    };
  }
};

template <class Input>
class QuadTree {
 public:
  explicit QuadTree(const Input& in) : in_(in) {}

  // Splits `n` into up to four non-empty children appended to `out`. Returns how many of them
  // hold more than one point (the ones that may split again).
  int split(const Node& n, std::vector<Node>& out) {
    const float xm = 0.5f * (n.x0 + n.x1), ym = 0.5f * (n.y0 + n.y1);
    const auto quadrant = in_.quadrants(xm, ym);
    std::array<int, 4> count{};
    scratch_.resize(static_cast<std::size_t>(n.size()));
    for (int i = n.begin; i < n.end; ++i) ++count[static_cast<std::size_t>(quadrant(idx_[static_cast<std::size_t>(i)]))];
    std::array<int, 4> pos{0, count[0], count[0] + count[1], count[0] + count[1] + count[2]};
    const std::array<int, 4> first = pos;
    for (int i = n.begin; i < n.end; ++i) {
      const int id = idx_[static_cast<std::size_t>(i)];
      const int q = quadrant(id);
      scratch_[static_cast<std::size_t>(pos[static_cast<std::size_t>(q)]++)] = id;
    }
    std::copy(scratch_.begin(), scratch_.end(), idx_.begin() + n.begin);
    const std::array<std::array<float, 4>, 4> boxes{{{n.x0, n.y0, xm, ym}, {xm, n.y0, n.x1, ym},
                                                      {n.x0, ym, xm, n.y1}, {xm, ym, n.x1, n.y1}}};
    int splittable = 0;
    for (std::size_t q = 0; q < 4; ++q) {
      if (count[q] == 0) continue;
      const auto& b = boxes[q];
      out.push_back({b[0], b[1], b[2], b[3], n.begin + first[q], n.begin + first[q] + count[q]});
      if (count[q] > 1) ++splittable;
    }
    return splittable;
  }

  std::vector<int> idx_;

 private:
  const Input& in_;
  std::vector<int> scratch_;
};

template <class Input>
std::vector<int> select(const Input& in, int target, cv::Size size) {
  const int k = static_cast<int>(in.size());
  if (target <= 0 || k == 0) return {};
  QuadTree<Input> tree(in);
  // Initial nodes: as many square-ish columns as the aspect ratio asks for (at least one).
  const int n_ini = std::max(1, static_cast<int>(std::lround(static_cast<double>(size.width) / size.height)));
  const float hx = static_cast<float>(size.width) / static_cast<float>(n_ini);
  std::vector<std::vector<int>> columns(static_cast<std::size_t>(n_ini));
  const auto column_of = in.columns(hx, n_ini);
  for (int i = 0; i < k; ++i) {
    const int c = column_of(i);
    columns[static_cast<std::size_t>(c)].push_back(i);
  }
  std::vector<Node> nodes, next;
  tree.idx_.reserve(static_cast<std::size_t>(k));
  for (int c = 0; c < n_ini; ++c) {
    const auto& col = columns[static_cast<std::size_t>(c)];
    if (col.empty()) continue;
    const int begin = static_cast<int>(tree.idx_.size());
    tree.idx_.insert(tree.idx_.end(), col.begin(), col.end());
    nodes.push_back({hx * static_cast<float>(c), 0.f, hx * static_cast<float>(c + 1), static_cast<float>(size.height),
                     begin, static_cast<int>(tree.idx_.size())});
  }

  // Rounds where every node with more than one point splits, until the node count reaches the
  // target; when a full round would overshoot, split the most populated nodes first (ORB-SLAM2).
  bool finished = false;
  while (!finished) {
    next.clear();
    int to_expand = 0;
    for (const Node& n : nodes) {
      if (n.size() <= 1) {
        next.push_back(n);
      } else {
        to_expand += tree.split(n, next);
      }
    }
    nodes.swap(next);
    // ORB-SLAM2 stops when the node count did not change, which also stops when every point fell
    // into one child; stopping only when no node can split any more is the intended criterion.
    if (static_cast<int>(nodes.size()) >= target || to_expand == 0) break;
    if (static_cast<int>(nodes.size()) + 3 * to_expand > target) {
      while (!finished) {
        // Largest first; stable so the result does not depend on the sort implementation.
        std::vector<std::size_t> expandable;
        for (std::size_t i = 0; i < nodes.size(); ++i)
          if (nodes[i].size() > 1) expandable.push_back(i);
        if (expandable.empty()) break;
        std::stable_sort(expandable.begin(), expandable.end(),
                         [&](std::size_t a, std::size_t b) { return nodes[a].size() > nodes[b].size(); });
        std::vector<char> removed(nodes.size(), 0);
        std::vector<Node> added;
        std::size_t count = nodes.size();
        for (std::size_t i : expandable) {
          const std::size_t children_before = added.size();
          tree.split(nodes[i], added);
          removed[i] = 1;
          count += added.size() - children_before - 1;
          if (static_cast<int>(count) >= target) {
            finished = true;
            break;
          }
        }
        next.clear();
        for (std::size_t i = 0; i < nodes.size(); ++i)
          if (!removed[i]) next.push_back(nodes[i]);
        next.insert(next.end(), added.begin(), added.end());
        nodes.swap(next);
      }
    }
  }

  std::vector<int> kept;
  kept.reserve(nodes.size());
  for (const Node& n : nodes) {
    int best = tree.idx_[static_cast<std::size_t>(n.begin)];
    for (int i = n.begin + 1; i < n.end; ++i) {
      const int id = tree.idx_[static_cast<std::size_t>(i)];
      if (in.response(id) > in.response(best)) best = id;
    }
    kept.push_back(best);
  }
  std::stable_sort(kept.begin(), kept.end(), [&](int a, int b) { return in.response(a) > in.response(b); });
  if (static_cast<int>(kept.size()) > target) kept.resize(static_cast<std::size_t>(target));
  return kept;
}

}  // namespace

std::vector<int> quadtree_select(const std::vector<cv::KeyPoint>& keypoints, int target, cv::Size size) {
  return select(KeyPointInput{keypoints}, target, size);
}

std::vector<int> quadtree_select(const FastCorners& corners, int target, cv::Size size) {
  return select(CornerInput{corners}, target, size);
}

}  // namespace plslam::features
