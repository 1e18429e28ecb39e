#include "plslam/features/ssc.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <cstring>
#include <memory>
#include <numeric>
#include <stdexcept>

#include "plslam/core/cpu_features.h"

#ifdef __SSE2__
#include <emmintrin.h>
#endif
#if defined(__x86_64__) || defined(__i386__)
#include <immintrin.h>
#define PLSLAM_SSC_AVX2 1
#endif

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

namespace detail {
namespace {
thread_local bool portable_only = false;
}
bool ssc_portable_only() { return portable_only; }
PortableSscScope::PortableSscScope() : previous_(portable_only) { portable_only = true; }
PortableSscScope::~PortableSscScope() { portable_only = previous_; }
}  // namespace detail

namespace {

// An uninitialised buffer that only grows: no allocation or zero-fill per call.
template <class T>
class Scratch {
 public:
  T* get(std::size_t n) {
    if (n > size_) {
      data_ = std::make_unique_for_overwrite<T[]>(n);
      size_ = n;
    }
    return data_.get();
  }

 private:
  std::unique_ptr<T[]> data_;
  std::size_t size_ = 0;
};

// Per-thread buffers (extract() runs the left and right image concurrently), reused by every
// call on the thread.
struct Workspace {
  Scratch<int> index, col_of_x, row_of_y;
  std::array<Scratch<int>, 2> kept;  // the current pass and the best one so far
  Scratch<uint32_t> position;
  Scratch<uint64_t> run_marks;  // gather_kept's run starts
  Scratch<int> run_rank;
  // The cover grid of a pass: a cell is covered when it holds the pass's stamp, so that a new
  // pass needs no clearing (only when the stamps wrap around or the grid grows).
  Scratch<uint8_t> grid;
  std::size_t grid_size = 0;
  uint8_t stamp = 0;
  uint8_t* grid_for_pass(std::size_t bytes) {
    if (bytes > grid_size) {
      grid_size = std::max(bytes, grid_size * 2);
      std::fill_n(grid.get(grid_size), grid_size, uint8_t{0});
      stamp = 0;
    }
    if (++stamp == 0) {
      std::fill_n(grid.get(grid_size), grid_size, uint8_t{0});
      stamp = 1;
    }
    return grid.get(grid_size);
  }
};
Workspace& workspace() {
  thread_local Workspace w;
  return w;
}

// Candidates in visiting order (strongest first): original index (keypoint path only; null for
// corners) and integer pixel position packed as y << 16 | x. The covering works on whole pixels (FAST corners are whole pixels).
// `position` is followed by kPadding entries of pixel (0, 0) (pad_sorted), so that a scan can
// read its last block whole and mask the bits past the end instead of finishing one candidate
// at a time.
struct SortedCandidates {
  const int* index;
  const uint32_t* position;
  int size;
};
constexpr int kPadding = 64;
void pad_sorted(uint32_t* position, int size) { std::fill_n(position + size, kPadding, uint32_t{0}); }

constexpr int kScoreBins = 256;  // FAST scores are below 256

// The keypoint path's visiting order and positions (generic callers and tests; the extractor
// passes FastCorners): order_by_response, and whole pixels clamped into the image as floats, NaN
// to 0, so that the integer conversions are always defined.
SortedCandidates sort_candidates(const std::vector<cv::KeyPoint>& keypoints, cv::Size size, Workspace& ws) {
  const int k = static_cast<int>(keypoints.size());
  const auto n = static_cast<std::size_t>(k);
  int* index = ws.index.get(n);
  uint32_t* position = ws.position.get(n + kPadding);
  pad_sorted(position, k);
  const auto x_max = static_cast<float>(size.width - 1), y_max = static_cast<float>(size.height - 1);
  const std::vector<int> order = order_by_response(keypoints);
  for (std::size_t i = 0; i < n; ++i) {
    const cv::Point2f& pt = keypoints[static_cast<std::size_t>(order[i])].pt;
    const float x = std::min(pt.x > 0.f ? pt.x : 0.f, x_max);
    const float y = std::min(pt.y > 0.f ? pt.y : 0.f, y_max);
    index[i] = order[i];
    position[i] = FastCorners::pack(static_cast<int>(x), static_cast<int>(y));
  }
  return {index, position, k};
}

// The extent of a corner set: largest x and y, smallest and largest score.
struct CornerExtent {
  uint32_t max_x = 0, max_y = 0;
  int min_score = kScoreBins - 1, max_score = 0;
};

CornerExtent corner_extent_portable(const FastCorners& corners) {
  CornerExtent e;
  uint32_t mx = 0, my = 0;
  for (const uint32_t p : corners.position) {
    mx = std::max(mx, p & 0xFFFFu);
    my = std::max(my, p >> 16);
  }
  uint8_t lo = kScoreBins - 1, hi = 0;
  for (const uint8_t s : corners.score) {
    lo = std::min(lo, s);
    hi = std::max(hi, s);
  }
  e.max_x = mx;
  e.max_y = my;
  e.min_score = lo;
  e.max_score = hi;
  return e;
}

#ifdef PLSLAM_SSC_AVX2
#if defined(__clang__)  // clang spells GCC's target pragma differently (fuzz builds use clang)
#pragma clang attribute push(__attribute__((target("avx2"))), apply_to = function)
#else
#pragma GCC push_options
#pragma GCC target("avx2")
#endif
// As corner_extent_portable, 16 coordinates or 32 scores per instruction.
CornerExtent corner_extent_avx2(const FastCorners& corners) {
  const std::size_t n = corners.size();
  const uint32_t* p = corners.position.data();
  const uint8_t* s = corners.score.data();
  __m256i max_xy = _mm256_setzero_si256();  // 16-bit lanes: x, y, x, y, ...
  std::size_t i = 0;
  for (; i + 8 <= n; i += 8) max_xy = _mm256_max_epu16(max_xy, _mm256_loadu_si256(reinterpret_cast<const __m256i*>(p + i)));
  alignas(32) std::array<uint16_t, 16> xy{};
  _mm256_store_si256(reinterpret_cast<__m256i*>(xy.data()), max_xy);
  CornerExtent e;
  for (std::size_t j = 0; j < 16; j += 2) {
    e.max_x = std::max<uint32_t>(e.max_x, xy[j]);
    e.max_y = std::max<uint32_t>(e.max_y, xy[j + 1]);
  }
  for (; i < n; ++i) {
    e.max_x = std::max(e.max_x, p[i] & 0xFFFFu);
    e.max_y = std::max(e.max_y, p[i] >> 16);
  }
  __m256i lo = _mm256_set1_epi8(-1), hi = _mm256_setzero_si256();
  std::size_t j = 0;
  for (; j + 32 <= n; j += 32) {
    const __m256i v = _mm256_loadu_si256(reinterpret_cast<const __m256i*>(s + j));
    lo = _mm256_min_epu8(lo, v);
    hi = _mm256_max_epu8(hi, v);
  }
  alignas(32) std::array<uint8_t, 32> l{}, h{};
  _mm256_store_si256(reinterpret_cast<__m256i*>(l.data()), lo);
  _mm256_store_si256(reinterpret_cast<__m256i*>(h.data()), hi);
  int min_s = *std::min_element(l.begin(), l.end()), max_s = *std::max_element(h.begin(), h.end());
  for (; j < n; ++j) {
    min_s = std::min<int>(min_s, s[j]);
    max_s = std::max<int>(max_s, s[j]);
  }
  e.min_score = min_s;
  e.max_score = max_s;
  return e;
}
#if defined(__clang__)
#pragma clang attribute pop
#else
#pragma GCC pop_options
#endif
#endif

bool use_avx2();

CornerExtent corner_extent(const FastCorners& corners) {
#ifdef PLSLAM_SSC_AVX2
  if (use_avx2()) return corner_extent_avx2(corners);
#endif
  return corner_extent_portable(corners);
}

// The runs of equal scores in the sorted order, for recovering the scores of kept slots without
// branches (walking the runs alongside the slots mispredicts at most run changes, which are
// frequent among kept points): a bitmap marks the first slot of every non-empty run, and the
// rank of the run holding slot s is the number of marks in [0, s] (a prefix count per 64-bit
// word plus a popcount). run_score[r] is the score of the r-th run (from 1).
struct ScoreRuns {
  uint64_t* marks;  // ws.run_marks, sorted.size / 64 + 1 words
  std::array<uint8_t, kScoreBins + 2> run_score;
};

// Corners already hold packed positions and integer scores: the counting sort reads them
// directly (5 bytes per candidate) and scatters only positions; no index is needed, since the
// kept corners are returned as positions and scores (gather_kept). Counters are cleared and
// summed over the scores in use only (`extent`), and the score runs are marked on the way.
SortedCandidates sort_corners(const FastCorners& corners, const CornerExtent& extent, Workspace& ws, ScoreRuns& runs) {
  const int k = static_cast<int>(corners.size());
  uint32_t* position = ws.position.get(static_cast<std::size_t>(k) + kPadding);
  pad_sorted(position, k);
  const SortedCandidates s{nullptr, position, k};
  const uint8_t* score = corners.score.data();
  const uint32_t* pos = corners.position.data();
  // FAST scores crowd into a few values, so one counter per score would chain every increment
  // through the same memory word: the input is split into four consecutive parts with their own
  // counters (four independent chains; stable, since part q's run of a score is placed after the
  // runs of parts 0..q-1). The four counters of a score are adjacent, so that the prefix sum
  // handles a score in one 128-bit vector.
  constexpr int kParts = 4;
  alignas(16) std::array<int, kScoreBins * kParts> next;  // next[score * kParts + part]
  const int lo = extent.min_score, hi = extent.max_score;
  std::fill(next.begin() + lo * kParts, next.begin() + (hi + 1) * kParts, 0);
  std::array<int, kParts + 1> part_begin{};
  for (int q = 0; q <= kParts; ++q) part_begin[static_cast<std::size_t>(q)] = static_cast<int>(static_cast<int64_t>(k) * q / kParts);
  const int common = k / kParts;
  auto for_each_part = [&](auto&& f) {
    for (int j = 0; j < common; ++j)
      for (int q = 0; q < kParts; ++q) f(q, part_begin[static_cast<std::size_t>(q)] + j);
    for (int q = 0; q < kParts; ++q)
      for (int i = part_begin[static_cast<std::size_t>(q)] + common; i < part_begin[static_cast<std::size_t>(q) + 1]; ++i) f(q, i);
  };
  for_each_part([&](int q, int i) { ++next[static_cast<std::size_t>(score[i] * kParts + q)]; });
  // Counts -> first output slot of each (score, part), strongest score first; a non-empty score
  // starts a run at its first slot. The run marks are built a word at a time in a register and
  // stored, never read back (run starts only grow).
  const auto words = static_cast<std::size_t>(k / 64 + 1);
  runs.marks = ws.run_marks.get(words);
  std::fill_n(runs.marks, words, uint64_t{0});
  uint64_t word = 0;
  std::size_t word_index = 0;
  int run_count = 0;
  auto mark_run = [&](int sc, int first, bool full) {
    const std::size_t w = static_cast<std::size_t>(first) >> 6;
    runs.marks[word_index] = word;  // final once w moves on
    // Keeps the word while w stays (a mask, not a branch: w moves on at unpredictable scores).
    const uint64_t stay = uint64_t{0} - static_cast<uint64_t>(w == word_index);
    word = (word & stay) | uint64_t{full} << (first & 63);
    word_index = w;
    runs.run_score[static_cast<std::size_t>(run_count) + 1] = static_cast<uint8_t>(sc);  // kept only if full
    run_count += full;
  };
  // Per score the four part counts become their first output slots. The scalar loop chains four
  // adds per score; the SSE2 one takes the exclusive prefix of the four counts in a vector and
  // keeps the running offset in all lanes, one vector add per score on the chain. (The scalar
  // loop also serves as the portable reference in tests.)
  auto prefix_scalar = [&] {
    int offset = 0;
    for (int sc = hi; sc >= lo; --sc) {
      const int first = offset;
      for (int q = 0; q < kParts; ++q) {
        int& c = next[static_cast<std::size_t>(sc * kParts + q)];
        const int count = c;
        c = offset;
        offset += count;
      }
      mark_run(sc, first, offset != first);
    }
  };
#ifdef __SSE2__
  static_assert(kParts == 4, "one 128-bit vector per score");
  if (!detail::ssc_portable_only()) {
    __m128i offset = _mm_setzero_si128();
    for (int sc = hi; sc >= lo; --sc) {
      auto* cell = reinterpret_cast<__m128i*>(next.data() + sc * kParts);
      const __m128i c = _mm_load_si128(cell);
      const __m128i incl2 = _mm_add_epi32(c, _mm_slli_si128(c, 4));
      const __m128i incl = _mm_add_epi32(incl2, _mm_slli_si128(incl2, 8));  // c0, c0+c1, ...
      _mm_store_si128(cell, _mm_add_epi32(offset, _mm_sub_epi32(incl, c)));
      const int first = _mm_cvtsi128_si32(offset);
      offset = _mm_add_epi32(offset, _mm_shuffle_epi32(incl, 0xFF));
      mark_run(sc, first, _mm_cvtsi128_si32(offset) != first);
    }
  } else {
    prefix_scalar();
  }
#else
  prefix_scalar();
#endif
  runs.marks[word_index] = word;
  for_each_part([&](int q, int i) { position[next[static_cast<std::size_t>(score[i] * kParts + q)]++] = pos[i]; });
  return s;
}

// Positions and scores of the sorted slots `slots[0, n)` (see ScoreRuns).
inline void gather_kept_impl(const SortedCandidates& sorted, const ScoreRuns& runs, const int* slots, int n,
                             FastCorners& out, Workspace& ws) {
  out.resize(static_cast<std::size_t>(n));
  uint32_t* out_position = out.position.data();
  uint8_t* out_score = out.score.data();
  const uint32_t* position = sorted.position;
  const auto words = static_cast<std::size_t>(sorted.size / 64 + 1);
  const uint64_t* marks = runs.marks;
  int* below = ws.run_rank.get(words);
  auto popcount = [](uint64_t v) { return __builtin_popcountll(v); };
  int total = 0;
  for (std::size_t w = 0; w < words; ++w) {
    below[w] = total;
    total += popcount(marks[w]);
  }
  for (int i = 0; i < n; ++i) {
    const auto slot = static_cast<uint32_t>(slots[i]);
    const std::size_t w = slot >> 6;
    const int rank = below[w] + popcount(marks[w] & (~uint64_t{0} >> (63 - (slot & 63))));
    out_position[i] = position[slot];
    out_score[i] = runs.run_score[static_cast<std::size_t>(rank)];
  }
}

#ifdef PLSLAM_SSC_AVX2
#if defined(__clang__)
#pragma clang attribute push(__attribute__((target("popcnt"))), apply_to = function)
#else
#pragma GCC push_options
#pragma GCC target("popcnt")
#endif
// The same, inlined here so that the popcounts become POPCNT instructions.
[[gnu::flatten]] void gather_kept_popcnt(const SortedCandidates& sorted, const ScoreRuns& runs, const int* slots, int n,
                                         FastCorners& out, Workspace& ws) {
  gather_kept_impl(sorted, runs, slots, n, out, ws);
}
#if defined(__clang__)
#pragma clang attribute pop
#else
#pragma GCC pop_options
#endif
#endif

void gather_kept(const SortedCandidates& sorted, const ScoreRuns& runs, const int* slots, int n, FastCorners& out,
                 Workspace& ws) {
#ifdef PLSLAM_SSC_AVX2
  static const bool has_popcnt = __builtin_cpu_supports("popcnt");
  if (has_popcnt && !detail::ssc_portable_only()) return gather_kept_popcnt(sorted, runs, slots, n, out, ws);
#endif
  gather_kept_impl(sorted, runs, slots, n, out, ws);
}

// The cell of pixel coordinate x at width w is floor(2x / w) (cells of side w/2), computed as
// trunc((x + 1/4) * fl(2/w)) in float arithmetic, which SIMD code can do for many candidates at
// once. Exact for x < 2^21: the true value (2x + 1/2)/w lies at least 1/(2w) away from an
// integer, while the two float roundings move it by at most 2^-23 (2x + 1/2)/w, less than that.
inline int cell_of(uint32_t x, float two_over_w) {
  return static_cast<int>((static_cast<float>(x) + 0.25f) * two_over_w);
}

// The cover grid of one pass: w/2 cells plus two margin cells on each side, so that covering a
// 5x5 block needs no bounds checks; 8 spare bytes for 32-bit gathers and 8-byte writes at the
// last cells.
struct Grid {
  int w, cols, rows, stride;
  float two_over_w;
  std::size_t cells;
  Grid(cv::Size size, int width)
      : w(width),
        cols((2 * (size.width - 1)) / width + 1),
        rows((2 * (size.height - 1)) / width + 1),
        stride(cols + 4),
        two_over_w(2.0f / static_cast<float>(width)),
        cells(static_cast<std::size_t>(stride) * static_cast<std::size_t>(rows + 4)) {}
  int cell_of_coordinate(uint32_t x) const { return cell_of(x, two_over_w); }
};

// Covers the 5x5 cells around `cell` with `stamp`: per row a 4-byte and a 1-byte store. Plain
// stores, no read-modify-write: a wider load overlapping an earlier store at another offset
// cannot be forwarded and stalls (measured 2x slower keeps).
inline void mark_cover(uint8_t* cell, int stride, uint8_t stamp) {
  const uint32_t four = 0x01010101u * stamp;
  for (int dy = -2; dy <= 2; ++dy) {
    uint8_t* row = cell + dy * stride - 2;
    std::memcpy(row, &four, 4);
    row[4] = stamp;
  }
}

// Keeps the candidates of one block of up to 32 whose cells were free (bits of free_mask) when
// the block started, in order, re-checking each (a point kept earlier in the block may have
// covered it). Returns false once `limit` points are kept.
inline bool keep_free(uint64_t free_mask, const int* cell_of_block, int first, uint8_t* g, int stride, uint8_t stamp,
                      int limit, int* kept, int& count) {
  while (free_mask) {
    const int j = __builtin_ctzll(free_mask);
    free_mask &= free_mask - 1u;
    uint8_t* cell = g + cell_of_block[j];
    if (*cell == stamp) continue;
    kept[count++] = first + j;
    if (count >= limit) return false;
    mark_cover(cell, stride, stamp);
  }
  return true;
}

// Portable scan over blocks of 32: the cells come from per-pass lookup tables (no conversion
// per candidate), and which candidates find their cell free is computed without branches (most
// are covered, few kept, so a branch per candidate would be mispredicted at every keep).
int scan_portable(const SortedCandidates& sorted, const Grid& grid, cv::Size size, uint8_t* g, uint8_t stamp, int limit,
                  int* kept, Workspace& ws) {
  int* cx = ws.col_of_x.get(static_cast<std::size_t>(size.width));
  int* ry = ws.row_of_y.get(static_cast<std::size_t>(size.height));
  for (int x = 0; x < size.width; ++x) cx[x] = cell_of(static_cast<uint32_t>(x), grid.two_over_w) + 2;
  for (int y = 0; y < size.height; ++y) ry[y] = (cell_of(static_cast<uint32_t>(y), grid.two_over_w) + 2) * grid.stride;
  const uint32_t* p = sorted.position;
  const int n = sorted.size;
  int count = 0;
  constexpr int kBlock = 32;
  static_assert(kBlock <= kPadding);
  for (int i = 0; i < n; i += kBlock) {
    std::array<int, kBlock> cells;
    uint32_t free_mask = 0;
#pragma GCC unroll 32
    for (int j = 0; j < kBlock; ++j) {
      const uint32_t pj = p[i + j];
      const int c = ry[pj >> 16] + cx[pj & 0xFFFFu];
      cells[static_cast<std::size_t>(j)] = c;
      free_mask |= static_cast<uint32_t>(g[c] != stamp) << j;
    }
    if (n - i < kBlock) free_mask &= (uint32_t{1} << (n - i)) - 1u;  // the padding past the end
    if (!keep_free(free_mask, cells.data(), i, g, grid.stride, stamp, limit, kept, count)) return count;
  }
  return count;
}

#ifdef PLSLAM_SSC_AVX2
#if defined(__clang__)
#pragma clang attribute push(__attribute__((target("avx2"))), apply_to = function)
#else
#pragma GCC push_options
#pragma GCC target("avx2")
#endif
// AVX2 scan: cells of 8 candidates at once by the float formula (no tables to fill per pass),
// their cover state by one gather.
int scan_avx2(const SortedCandidates& sorted, const Grid& grid, uint8_t* g, uint8_t stamp, int limit, int* kept) {
  const uint32_t* p = sorted.position;
  const int n = sorted.size;
  const __m256i low16 = _mm256_set1_epi32(0xFFFF), two = _mm256_set1_epi32(2), low8 = _mm256_set1_epi32(0xFF);
  const __m256i stride = _mm256_set1_epi32(grid.stride), covered = _mm256_set1_epi32(stamp);
  const __m256 quarter = _mm256_set1_ps(0.25f), scale = _mm256_set1_ps(grid.two_over_w);
  int count = 0;
  constexpr int kBlock = 64;
  static_assert(kBlock <= kPadding);
  for (int i = 0; i < n; i += kBlock) {
    alignas(32) int cells[kBlock];
    uint64_t free_mask = 0;
    for (int h = 0; h < kBlock / 8; ++h) {
      const __m256i pos = _mm256_loadu_si256(reinterpret_cast<const __m256i*>(p + i + 8 * h));
      const __m256i x = _mm256_and_si256(pos, low16), y = _mm256_srli_epi32(pos, 16);
      const __m256i cx = _mm256_cvttps_epi32(_mm256_mul_ps(_mm256_add_ps(_mm256_cvtepi32_ps(x), quarter), scale));
      const __m256i cy = _mm256_cvttps_epi32(_mm256_mul_ps(_mm256_add_ps(_mm256_cvtepi32_ps(y), quarter), scale));
      const __m256i c = _mm256_add_epi32(_mm256_mullo_epi32(_mm256_add_epi32(cy, two), stride), _mm256_add_epi32(cx, two));
      _mm256_store_si256(reinterpret_cast<__m256i*>(cells + 8 * h), c);
      const __m256i state = _mm256_and_si256(_mm256_i32gather_epi32(reinterpret_cast<const int*>(g), c, 1), low8);
      const auto bits = static_cast<uint32_t>(_mm256_movemask_ps(_mm256_castsi256_ps(_mm256_cmpeq_epi32(state, covered))));
      free_mask |= static_cast<uint64_t>(~bits & 0xFFu) << (8 * h);
    }
    if (n - i < kBlock) free_mask &= (uint64_t{1} << (n - i)) - 1u;  // the padding past the end
    if (!keep_free(free_mask, cells, i, g, grid.stride, stamp, limit, kept, count)) return count;
  }
  return count;
}
#if defined(__clang__)
#pragma clang attribute pop
#else
#pragma GCC pop_options
#endif
#endif

bool use_avx2() {
#ifdef PLSLAM_SSC_AVX2
  return core::cpu_has_avx2() && !detail::ssc_portable_only();
#else
  return false;
#endif
}

// One greedy covering pass at width w over the sorted candidates. Stops once `limit` points are
// kept (the caller then only needs to know it overshot). Returns the kept count; the sorted
// positions of the kept points are in kept()[0, count).
class Coverer {
 public:
  Coverer(const SortedCandidates& sorted, cv::Size size, Workspace& ws) : sorted_(sorted), size_(size), ws_(ws) {}

  // Writes the sorted positions of the kept points to kept (room for `limit`).
  int run(int w, int limit, int* kept) {
    const Grid grid(size_, w);
    uint8_t* g = ws_.grid_for_pass(grid.cells + 8);
    const uint8_t stamp = ws_.stamp;
#ifdef PLSLAM_SSC_AVX2
    if (use_avx2() && grid.cells < (std::size_t{1} << 31)) return scan_avx2(sorted_, grid, g, stamp, limit, kept);
#endif
    return scan_portable(sorted_, grid, size_, g, stamp, limit, kept, ws_);
  }

 private:
  SortedCandidates sorted_;
  cv::Size size_;
  Workspace& ws_;
};

}  // namespace

namespace detail {
int ssc_cell(uint32_t x, int w) { return Grid(cv::Size(1, 1), w).cell_of_coordinate(x); }
}  // namespace detail

namespace {

// The outcome of the width search over sorted candidates: the kept ones as sorted positions
// (slots), strongest first.
struct Selection {
  const int* slots = nullptr;
  int count = 0;
  double width = 0;
  int iterations = 0;
};

// The search for the widest covering that keeps `target` (+- tolerance) of the k > target
// sorted candidates.
Selection search_width(const SortedCandidates& sorted, int target, cv::Size size, double tolerance_fraction,
                       double width_hint, Workspace& ws) {
  Selection result;
  const int k = sorted.size;
  const int tolerance = static_cast<int>(std::floor(tolerance_fraction * target));
  const SscBounds bounds = ssc_width_bounds(k, target, size);

  Coverer cover(sorted, size, ws);
  // Passes write into one of two buffers; a pass worth keeping becomes `best` by swapping roles.
  const auto room = static_cast<std::size_t>(target + tolerance + 1);
  std::array<int*, 2> buffers{ws.kept[0].get(room), ws.kept[1].get(room)};
  int current = 0;
  const int* best = nullptr;
  int best_count = 0;
  double best_width = 0;
  // Integer widths, as in Bailo et al.: the count changes in steps anyway, and the search
  // ends after about log2(w_high) passes.
  int low = static_cast<int>(std::floor(bounds.low));
  int high = static_cast<int>(std::ceil(bounds.high));
  bool done = false;
  // One probe: true when the search is over (count within tolerance).
  auto probe = [&](int w) {
    const int count = cover.run(w, target + tolerance + 1, buffers[static_cast<std::size_t>(current)]);
    ++result.iterations;
    auto keep_pass = [&] {
      best = buffers[static_cast<std::size_t>(current)];
      best_count = count;
      best_width = w;
      current ^= 1;
    };
    if (std::abs(count - target) <= tolerance) {
      keep_pass();
      return true;
    }
    if (count > target) {
      keep_pass();  // feasible: remember it, then try wider
      low = std::max(low, w + 1);
    } else {
      high = std::min(high, w - 1);
    }
    return false;
  };
  const int hint = static_cast<int>(std::lround(width_hint));
  if (hint >= low && hint <= high) {
    // Gallop from the hint (steps 1, 1, 2, 4, ...) in the direction its outcome points to, until
    // the outcome flips; the bisection then finishes inside the bracket. A hint that is right
    // or off by one costs two or three passes instead of a bisection over the whole range.
    int w = hint;
    done = probe(w);
    const bool wider = low > w;  // feasible at the hint: the widest feasible width is above
    for (int n = 0; !done && low <= high && (low > w) == wider; ++n) {
      const int step = n < 2 ? 1 : 1 << (n - 1);  // 1, 1, 2, 4, ...: widths drift slowly
      w = wider ? std::min(w + step, high) : std::max(w - step, low);
      done = probe(w);
    }
  }
  while (!done && low <= high) done = probe(low + (high - low) / 2);
  if (!done && best == nullptr) {
    // Only possible with duplicate positions: fall back to the narrowest cover.
    const int w = std::max(1, static_cast<int>(std::floor(bounds.low)));
    best_width = w;
    best = buffers[static_cast<std::size_t>(current)];
    best_count = cover.run(w, target, buffers[static_cast<std::size_t>(current)]);
    ++result.iterations;
  }
  if (best_count > target + tolerance) best_count = target;
  result.slots = best;
  result.count = best_count;
  result.width = best_width;
  return result;
}

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
  Workspace& ws = workspace();
  const SortedCandidates sorted = sort_candidates(keypoints, size, ws);
  const Selection sel = search_width(sorted, target, size, tolerance_fraction, width_hint, ws);
  result.width = sel.width;
  result.iterations = sel.iterations;
  result.kept.resize(static_cast<std::size_t>(sel.count));
  for (int i = 0; i < sel.count; ++i) result.kept[static_cast<std::size_t>(i)] = sorted.index[sel.slots[i]];
  return result;
}

SscCornersResult ssc_select(const FastCorners& corners, int target, cv::Size size, double tolerance_fraction,
                            double width_hint) {
  SscCornersResult result;
  const int k = static_cast<int>(corners.size());
  if (corners.score.size() != corners.position.size()) throw std::invalid_argument("ssc_select: corner arrays differ in length");
  if (target <= 0 || k == 0 || size.width < 1 || size.height < 1) return result;
  if (size.width > 65535 || size.height > 65535) throw std::invalid_argument("ssc_select: image too large");
  const CornerExtent extent = corner_extent(corners);
  if (extent.max_x >= static_cast<uint32_t>(size.width) || extent.max_y >= static_cast<uint32_t>(size.height))
    throw std::invalid_argument("ssc_select: corner outside the image");
  Workspace& ws = workspace();
  ScoreRuns runs;
  const SortedCandidates sorted = sort_corners(corners, extent, ws, runs);
  if (k <= target) {
    std::vector<int> all(static_cast<std::size_t>(k));
    std::iota(all.begin(), all.end(), 0);
    gather_kept(sorted, runs, all.data(), k, result.kept, ws);
    return result;
  }
  const Selection sel = search_width(sorted, target, size, tolerance_fraction, width_hint, ws);
  result.width = sel.width;
  result.iterations = sel.iterations;
  gather_kept(sorted, runs, sel.slots, sel.count, result.kept, ws);
  return result;
}

}  // namespace plslam::features
