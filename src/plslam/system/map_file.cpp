#include "plslam/system/map_file.h"

#include <fcntl.h>
#include <sys/mman.h>
#include <sys/stat.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <cmath>
#include <cstring>
#include <fstream>
#include <future>
#include <set>
#include <stdexcept>
#include <type_traits>
#include <unordered_map>

#include <fmt/format.h>
#include <spdlog/spdlog.h>

#include "plslam/core/error.h"
#include "plslam/core/input_file.h"
#include "plslam/io/atomic_file.h"

namespace plslam::system {
namespace {

constexpr char kMagic[8] = {'p', 'l', 's', 'l', 'm', 'a', 'p', '\0'};
constexpr char kSectionTags[6][5] = {"META", "KFRM", "MPTS", "MLIN", "GRPH", "IMUS"};
constexpr std::uint32_t kVersion1Sections = 5;
constexpr std::size_t kImuSampleBytes = 7 * 8;
// Timestamps are written as read; an interval's ends are its keyframes' times to this (seconds).
constexpr double kImuTimeTolerance = 1e-6;
constexpr std::size_t kKeypointBytes = 5 * 4 + 2 * 4;
constexpr std::size_t kLineBytes = 5 * 4 + 4 + 12 * 8 + 1;
constexpr int kMaxLevels = 32;
constexpr long kMaxId = 1L << 40;  // ids count objects; anything above is corruption

std::uint64_t word_fnv1a(const char* data, std::size_t n) {
  std::uint64_t h = 14695981039346656037ull;
  std::size_t i = 0;
  for (; i + 8 <= n; i += 8) {
    std::uint64_t w;
    std::memcpy(&w, data + i, 8);
    h ^= w;
    h *= 1099511628211ull;
  }
  for (; i < n; ++i) {
    h ^= static_cast<unsigned char>(data[i]);
    h *= 1099511628211ull;
  }
  return h;
}

// ---------------------------------------------------------------------------------------------
// Writing

class Writer {
 public:
  template <typename T>
  void put(T v) {
    out_.append(reinterpret_cast<const char*>(&v), sizeof(T));
  }
  void put_bytes(const void* p, std::size_t n) { out_.append(static_cast<const char*>(p), n); }
  void put_count(std::size_t n) { put<std::uint32_t>(static_cast<std::uint32_t>(n)); }
  void put_string(const std::string& s) {
    put<std::uint64_t>(s.size());
    out_ += s;
  }
  void put_vec3(const Eigen::Vector3d& v) {
    for (int i = 0; i < 3; ++i) put<double>(v[i]);
  }
  void put_pose(const geometry::SE3& T) {
    for (int r = 0; r < 3; ++r) {
      for (int c = 0; c < 3; ++c) put<double>(T.rotation()(r, c));
    }
    put_vec3(T.translation());
  }
  // A 1 x 32 descriptor behind a presence byte.
  void put_descriptor(const cv::Mat& d) {
    const bool has = !d.empty() && d.total() == 32 && d.type() == CV_8U;
    put<std::uint8_t>(has);
    if (has) {
      const cv::Mat c = d.isContinuous() ? d : d.clone();
      put_bytes(c.data, 32);
    }
  }
  std::string& str() { return out_; }

 private:
  std::string out_;
};

void write_meta(Writer& w, const MapFileMeta& m) {
  const auto& c = m.calib;
  w.put<std::int32_t>(c.width);
  w.put<std::int32_t>(c.height);
  for (double v : {c.fx, c.fy, c.cx, c.cy, c.baseline}) w.put<double>(v);
  w.put<std::uint64_t>(m.vocabulary_checksum);
  w.put<std::uint32_t>(m.vocabulary_words);
  w.put<std::uint32_t>(m.vocabulary_nodes);
  w.put<std::int64_t>(m.next_ids.keyframe);
  w.put<std::int64_t>(m.next_ids.point);
  w.put<std::int64_t>(m.next_ids.line);
  w.put<std::uint8_t>(m.T_gt_map.has_value());
  if (m.T_gt_map) w.put_pose(*m.T_gt_map);
  w.put_string(m.created_by);
  w.put_string(m.config);
}

void write_keyframe(Writer& w, const SavedKeyframe& k) {
  const auto& d = *k.data;
  w.put<std::int64_t>(k.id);
  w.put_pose(k.T_cw);
  w.put<std::int64_t>(d.frame_id);
  w.put<double>(d.timestamp);
  w.put<std::int32_t>(d.levels);
  w.put<double>(d.scale_factor);
  w.put_count(d.keypoints.size());
  for (const auto& kp : d.keypoints) {
    for (float v : {kp.pt.x, kp.pt.y, kp.size, kp.angle, kp.response}) w.put<float>(v);
    w.put<std::int32_t>(kp.octave);
    w.put<std::int32_t>(kp.class_id);
  }
  if (!d.keypoints.empty()) w.put_bytes(d.descriptors.data, d.keypoints.size() * 32);
  w.put_bytes(d.u_right.data(), d.u_right.size() * 4);
  w.put_bytes(d.depth.data(), d.depth.size() * 4);
  w.put_count(d.lines.size());
  for (const auto& l : d.lines) {
    for (float v : {l.segment.start.x, l.segment.start.y, l.segment.end.x, l.segment.end.y, l.segment.response}) {
      w.put<float>(v);
    }
    w.put<std::int32_t>(l.segment.fragments);
    for (const auto* v : {&l.left_line, &l.right_line, &l.start_cam, &l.end_cam}) w.put_vec3(*v);
    w.put<std::uint8_t>(l.stereo);
  }
  if (!d.lines.empty()) w.put_bytes(d.line_descriptors.data, d.lines.size() * 32);
  w.put<std::uint8_t>(k.place != nullptr);
  if (k.place) {
    w.put_count(k.place->bow.size());
    for (const auto& [word, weight] : k.place->bow) {
      w.put<std::uint32_t>(word);
      w.put<double>(weight);
    }
    w.put_count(k.place->features.size());
    for (const auto& [node, indices] : k.place->features) {
      w.put<std::uint32_t>(node);
      w.put_count(indices.size());
      w.put_bytes(indices.data(), indices.size() * 4);
    }
  }
}

void write_landmark(Writer& w, const SavedLandmark& l, bool line) {
  w.put<std::int64_t>(l.id);
  w.put<std::int64_t>(l.created_frame);
  w.put<std::int64_t>(l.reference);
  w.put_vec3(l.a);
  if (line) {
    w.put_vec3(l.b);
  } else {
    w.put<double>(l.level0_max_distance);
  }
  w.put_vec3(l.state.normal);
  w.put<double>(l.state.min_distance);
  w.put<double>(l.state.max_distance);
  w.put_descriptor(l.state.descriptor);
  w.put<std::int32_t>(l.state.visible);
  w.put<std::int32_t>(l.state.found);
  w.put_count(l.observations.size());
  for (const auto& [kf, index] : l.observations) {
    w.put<std::int64_t>(kf);
    w.put<std::int32_t>(index);
  }
}

void write_graph(Writer& w, const SavedKeyframe& k) {
  w.put<std::int64_t>(k.id);
  w.put<std::int64_t>(k.parent);
  w.put_count(k.covisibility.size());
  for (const auto& [id, weight] : k.covisibility) {
    w.put<std::int64_t>(id);
    w.put<std::int32_t>(weight);
  }
  w.put_count(k.loop_edges.size());
  for (long id : k.loop_edges) w.put<std::int64_t>(id);
}

void write_imu_state(Writer& w, long id, const SavedImuState& s) {
  w.put<std::int64_t>(id);
  w.put_vec3(s.v);
  w.put_vec3(s.bias.gyro);
  w.put_vec3(s.bias.acc);
  w.put<std::uint8_t>(s.estimated);
  w.put<std::int64_t>(s.from_previous ? s.previous : -1);
  if (!s.from_previous) return;
  const auto& pim = *s.from_previous;
  w.put_vec3(pim.linearisation_bias().gyro);
  w.put_vec3(pim.linearisation_bias().acc);
  const auto& n = pim.noise();
  for (double v : {n.gyro_noise_density, n.gyro_random_walk, n.acc_noise_density, n.acc_random_walk}) w.put<double>(v);
  w.put_count(pim.samples().size());
  for (const auto& smp : pim.samples()) {
    w.put<double>(smp.t);
    w.put_vec3(smp.gyro);
    w.put_vec3(smp.acc);
  }
}

// ---------------------------------------------------------------------------------------------
// Reading

class Reader {
 public:
  Reader(const char* p, std::size_t n, const std::string& source, const char* section)
      : p_(p), end_(p + n), source_(source), section_(section) {}

  [[noreturn]] void fail(const std::string& problem) const {
    throw InputError(source_, fmt::format("section {}: {}", section_, problem));
  }
  std::size_t left() const { return static_cast<std::size_t>(end_ - p_); }
  const char* take(std::size_t n) {
    if (n > left()) fail("truncated");
    const char* at = p_;
    p_ += n;
    return at;
  }
  template <typename T>
  T get() {
    T v;
    std::memcpy(&v, take(sizeof(T)), sizeof(T));
    return v;
  }
  double get_finite() {
    const double v = get<double>();
    if (!std::isfinite(v)) fail("a number is not finite");
    return v;
  }
  // A count of records of at least `min_bytes` each: checked against the bytes left, so a
  // corrupt count never allocates more than the file holds.
  std::size_t count(std::size_t min_bytes) {
    const std::size_t n = get<std::uint32_t>();
    if (min_bytes > 0 && n > left() / min_bytes) fail(fmt::format("count {} exceeds the section", n));
    return n;
  }
  std::string get_string() {
    const auto n = get<std::uint64_t>();
    if (n > left()) fail("truncated string");
    return std::string(take(static_cast<std::size_t>(n)), static_cast<std::size_t>(n));
  }
  Eigen::Vector3d get_vec3() {
    Eigen::Vector3d v;
    for (int i = 0; i < 3; ++i) v[i] = get_finite();
    return v;
  }
  geometry::SE3 get_pose() {
    Eigen::Matrix3d R;
    for (int r = 0; r < 3; ++r) {
      for (int c = 0; c < 3; ++c) R(r, c) = get_finite();
    }
    const Eigen::Vector3d t = get_vec3();
    if (!(R.transpose() * R - Eigen::Matrix3d::Identity()).isZero(1e-6) || R.determinant() < 0) {
      fail("a pose is not a rotation");
    }
    return geometry::SE3(R, t);
  }
  long get_id(const char* what) {
    const auto id = get<std::int64_t>();
    if (id < 0 || id >= kMaxId) fail(fmt::format("{} id {} out of range", what, id));
    return static_cast<long>(id);
  }
  cv::Mat get_descriptor() {
    const auto has = get<std::uint8_t>();
    if (has > 1) fail("bad descriptor flag");
    if (!has) return {};
    cv::Mat d(1, 32, CV_8U);
    std::memcpy(d.data, take(32), 32);
    return d;
  }
  bool done() const { return p_ == end_; }

 private:
  const char* p_;
  const char* end_;
  const std::string& source_;
  const char* section_;
};

MapFileMeta read_meta(Reader& r) {
  MapFileMeta m;
  auto& c = m.calib;
  c.width = r.get<std::int32_t>();
  c.height = r.get<std::int32_t>();
  c.fx = r.get_finite();
  c.fy = r.get_finite();
  c.cx = r.get_finite();
  c.cy = r.get_finite();
  c.baseline = r.get_finite();
  if (c.width <= 0 || c.height <= 0 || c.width > 100000 || c.height > 100000 || c.fx <= 0 || c.fy <= 0 ||
      c.baseline <= 0) {
    r.fail(fmt::format("implausible calibration ({}x{}, fx {}, baseline {})", c.width, c.height, c.fx, c.baseline));
  }
  m.vocabulary_checksum = r.get<std::uint64_t>();
  m.vocabulary_words = r.get<std::uint32_t>();
  m.vocabulary_nodes = r.get<std::uint32_t>();
  if (m.vocabulary_words > m.vocabulary_nodes) r.fail("more vocabulary words than nodes");
  m.next_ids.keyframe = r.get_id("next keyframe");
  m.next_ids.point = r.get_id("next point");
  m.next_ids.line = r.get_id("next line");
  const auto has_anchor = r.get<std::uint8_t>();
  if (has_anchor > 1) r.fail("bad ground-truth anchor flag");
  if (has_anchor) m.T_gt_map = r.get_pose();
  m.created_by = r.get_string();
  m.config = r.get_string();
  return m;
}

SavedKeyframe read_keyframe(Reader& r, const MapFileMeta& meta) {
  SavedKeyframe k;
  k.id = r.get_id("keyframe");
  if (k.id >= meta.next_ids.keyframe) r.fail(fmt::format("keyframe id {} not below the next id", k.id));
  k.T_cw = r.get_pose();
  auto d = std::make_shared<map::FrameData>();
  d->calib = meta.calib;
  d->frame_id = r.get_id("frame");
  d->timestamp = r.get_finite();
  d->levels = r.get<std::int32_t>();
  d->scale_factor = r.get_finite();
  if (d->levels < 1 || d->levels > kMaxLevels || !(d->scale_factor > 1.0 && d->scale_factor < 4.0)) {
    r.fail(fmt::format("keyframe {}: implausible pyramid ({} levels, scale {})", k.id, d->levels, d->scale_factor));
  }
  // Each keypoint also has a descriptor (32 bytes), a right coordinate and a depth (4 each).
  const std::size_t n = r.count(kKeypointBytes + 40);
  d->keypoints.resize(n);
  const char* kp_bytes = r.take(n * kKeypointBytes);
  for (std::size_t i = 0; i < n; ++i) {
    float f[5];
    std::int32_t octave, class_id;
    std::memcpy(f, kp_bytes + i * kKeypointBytes, sizeof(f));
    std::memcpy(&octave, kp_bytes + i * kKeypointBytes + 20, 4);
    std::memcpy(&class_id, kp_bytes + i * kKeypointBytes + 24, 4);
    if (!std::isfinite(f[0]) || !std::isfinite(f[1]) || octave < 0 || octave >= d->levels) {
      r.fail(fmt::format("keyframe {}: bad keypoint {}", k.id, i));
    }
    d->keypoints[i] = cv::KeyPoint(f[0], f[1], f[2], f[3], f[4], octave, class_id);
  }
  d->descriptors.create(static_cast<int>(n), 32, CV_8U);
  if (n > 0) std::memcpy(d->descriptors.data, r.take(n * 32), n * 32);
  d->u_right.resize(n);
  d->depth.resize(n);
  if (n > 0) {
    std::memcpy(d->u_right.data(), r.take(n * 4), n * 4);
    std::memcpy(d->depth.data(), r.take(n * 4), n * 4);
  }
  for (std::size_t i = 0; i < n; ++i) {
    if (!std::isfinite(d->u_right[i]) || !std::isfinite(d->depth[i])) r.fail(fmt::format("keyframe {}: bad depth", k.id));
  }
  const std::size_t m = r.count(kLineBytes + 32);
  d->lines.resize(m);
  for (auto& l : d->lines) {
    float f[5];
    for (float& v : f) {
      v = r.get<float>();
      if (!std::isfinite(v)) r.fail(fmt::format("keyframe {}: bad line", k.id));
    }
    l.segment.start = {f[0], f[1]};
    l.segment.end = {f[2], f[3]};
    l.segment.response = f[4];
    l.segment.fragments = r.get<std::int32_t>();
    l.left_line = r.get_vec3();
    l.right_line = r.get_vec3();
    l.start_cam = r.get_vec3();
    l.end_cam = r.get_vec3();
    const auto stereo = r.get<std::uint8_t>();
    if (stereo > 1) r.fail(fmt::format("keyframe {}: bad line flag", k.id));
    l.stereo = stereo;
  }
  d->line_descriptors.create(static_cast<int>(m), 32, CV_8U);
  if (m > 0) std::memcpy(d->line_descriptors.data, r.take(m * 32), m * 32);
  if (m == 0) d->line_descriptors = cv::Mat();
  if (n == 0) d->descriptors = cv::Mat();
  d->build_grid();
  const auto has_place = r.get<std::uint8_t>();
  if (has_place > 1) r.fail(fmt::format("keyframe {}: bad place flag", k.id));
  if (has_place) {
    auto place = std::make_shared<place::PlaceDescription>();
    const std::size_t nb = r.count(12);
    place->bow.reserve(nb);
    for (std::size_t i = 0; i < nb; ++i) {
      const auto word = r.get<std::uint32_t>();
      const double weight = r.get_finite();
      if (word >= meta.vocabulary_words || (!place->bow.empty() && word <= place->bow.back().first)) {
        r.fail(fmt::format("keyframe {}: bad word {}", k.id, word));
      }
      place->bow.emplace_back(word, weight);
    }
    const std::size_t nf = r.count(8);
    place->features.reserve(nf);
    for (std::size_t i = 0; i < nf; ++i) {
      const auto node = r.get<std::uint32_t>();
      if (node >= meta.vocabulary_nodes || (!place->features.empty() && node <= place->features.back().first)) {
        r.fail(fmt::format("keyframe {}: bad vocabulary node {}", k.id, node));
      }
      const std::size_t count = r.count(4);
      std::vector<std::uint32_t> indices(count);
      if (count > 0) std::memcpy(indices.data(), r.take(count * 4), count * 4);
      for (auto idx : indices) {
        if (idx >= n) r.fail(fmt::format("keyframe {}: feature index {} out of range", k.id, idx));
      }
      place->features.emplace_back(node, std::move(indices));
    }
    k.place = std::move(place);
  }
  k.data = std::move(d);
  return k;
}

SavedLandmark read_landmark(Reader& r, bool line, long next_id) {
  SavedLandmark l;
  const char* what = line ? "line" : "point";
  l.id = r.get_id(what);
  if (l.id >= next_id) r.fail(fmt::format("{} id {} not below the next id", what, l.id));
  l.created_frame = r.get_id("frame");
  l.reference = r.get_id("reference keyframe");
  l.a = r.get_vec3();
  if (line) {
    l.b = r.get_vec3();
  } else {
    l.level0_max_distance = r.get_finite();
  }
  l.state.normal = r.get_vec3();
  l.state.min_distance = r.get_finite();
  l.state.max_distance = r.get_finite();
  l.state.descriptor = r.get_descriptor();
  l.state.visible = r.get<std::int32_t>();
  l.state.found = r.get<std::int32_t>();
  if (l.state.visible < 0 || l.state.found < 0) r.fail(fmt::format("{} {}: negative statistics", what, l.id));
  const std::size_t n = r.count(12);
  l.observations.reserve(n);
  for (std::size_t i = 0; i < n; ++i) {
    const long kf = r.get_id("observing keyframe");
    const auto index = r.get<std::int32_t>();
    if (!l.observations.empty() && kf <= l.observations.back().first) {
      r.fail(fmt::format("{} {}: observations not ordered by keyframe", what, l.id));
    }
    l.observations.emplace_back(kf, index);
  }
  return l;
}

void read_graph(Reader& r, SavedKeyframe& k) {
  if (r.get_id("keyframe") != k.id) r.fail(fmt::format("graph entry out of order at keyframe {}", k.id));
  const auto parent = r.get<std::int64_t>();
  if (parent < -1 || parent >= kMaxId) r.fail(fmt::format("keyframe {}: parent {} out of range", k.id, parent));
  k.parent = static_cast<long>(parent);
  const std::size_t nc = r.count(12);
  k.covisibility.reserve(nc);
  for (std::size_t i = 0; i < nc; ++i) {
    const long id = r.get_id("covisible keyframe");
    const int weight = r.get<std::int32_t>();
    if (weight < 0 || id == k.id || (!k.covisibility.empty() && id <= k.covisibility.back().first)) {
      r.fail(fmt::format("keyframe {}: bad covisibility edge to {}", k.id, id));
    }
    k.covisibility.emplace_back(id, weight);
  }
  const std::size_t nl = r.count(8);
  for (std::size_t i = 0; i < nl; ++i) {
    const long id = r.get_id("loop keyframe");
    if (id == k.id || (!k.loop_edges.empty() && id <= k.loop_edges.back())) {
      r.fail(fmt::format("keyframe {}: bad loop edge to {}", k.id, id));
    }
    k.loop_edges.push_back(id);
  }
}

// One IMU state; its keyframe and predecessor are checked in check_references. The preintegration
// is integrated again from the samples (what Preintegration refuses is an InputError here).
std::pair<long, SavedImuState> read_imu_state(Reader& r) {
  const long id = r.get_id("IMU state keyframe");
  SavedImuState s;
  s.v = r.get_vec3();
  s.bias.gyro = r.get_vec3();
  s.bias.acc = r.get_vec3();
  const auto estimated = r.get<std::uint8_t>();
  if (estimated > 1) r.fail(fmt::format("keyframe {}: bad IMU state flag", id));
  s.estimated = estimated == 1;
  const auto previous = r.get<std::int64_t>();
  if (previous < -1 || previous >= kMaxId) r.fail(fmt::format("keyframe {}: IMU predecessor {} out of range", id, previous));
  s.previous = static_cast<long>(previous);
  if (s.previous < 0) return {id, s};
  inertial::ImuBias lin;
  lin.gyro = r.get_vec3();
  lin.acc = r.get_vec3();
  ImuNoise noise;
  for (double* v : {&noise.gyro_noise_density, &noise.gyro_random_walk, &noise.acc_noise_density, &noise.acc_random_walk}) {
    *v = r.get_finite();
    if (*v < 0) r.fail(fmt::format("keyframe {}: negative IMU noise", id));
  }
  const std::size_t n = r.count(kImuSampleBytes);
  if (n < 2) r.fail(fmt::format("keyframe {}: {} IMU samples (at least 2)", id, n));
  std::vector<ImuSample> samples(n);
  for (auto& smp : samples) {
    smp.t = r.get_finite();
    smp.gyro = r.get_vec3();
    smp.acc = r.get_vec3();
  }
  for (std::size_t i = 1; i < n; ++i) {
    if (!(samples[i].t > samples[i - 1].t)) r.fail(fmt::format("keyframe {}: IMU sample times not increasing", id));
  }
  try {
    s.from_previous = std::make_shared<const inertial::Preintegration>(samples, samples.front().t, samples.back().t, lin, noise);
  } catch (const std::invalid_argument& e) {
    r.fail(fmt::format("keyframe {}: {}", id, e.what()));
  }
  return {id, s};
}

// Cross-references: every id a record names exists, every feature index lies in its keyframe and
// holds one landmark at most, and the spanning tree has no cycle.
void check_references(const MapContents& c, const std::string& source) {
  auto fail = [&](const std::string& problem) { throw InputError(source, problem); };
  std::unordered_map<long, std::size_t> index;  // keyframe id -> position in c.keyframes
  index.reserve(c.keyframes.size());
  for (std::size_t i = 0; i < c.keyframes.size(); ++i) index.emplace(c.keyframes[i].id, i);
  auto check_landmarks = [&](const std::vector<SavedLandmark>& ls, bool line) {
    const char* what = line ? "line" : "point";
    std::vector<std::vector<bool>> taken(c.keyframes.size());
    for (std::size_t k = 0; k < c.keyframes.size(); ++k) {
      const auto& d = *c.keyframes[k].data;
      taken[k].assign(line ? d.lines.size() : d.keypoints.size(), false);
    }
    for (std::size_t i = 0; i < ls.size(); ++i) {
      const auto& l = ls[i];
      if (i > 0 && l.id <= ls[i - 1].id) fail(fmt::format("{} ids not increasing at {}", what, l.id));
      if (!index.count(l.reference)) fail(fmt::format("{} {}: unknown reference keyframe {}", what, l.id, l.reference));
      for (const auto& [kf, feature] : l.observations) {
        const auto it = index.find(kf);
        if (it == index.end()) fail(fmt::format("{} {}: observed by unknown keyframe {}", what, l.id, kf));
        auto& slots = taken[it->second];
        if (feature < 0 || static_cast<std::size_t>(feature) >= slots.size()) {
          fail(fmt::format("{} {}: feature index {} out of range in keyframe {}", what, l.id, feature, kf));
        }
        if (slots[static_cast<std::size_t>(feature)]) {
          fail(fmt::format("{} {}: feature {} of keyframe {} holds two {}s", what, l.id, feature, kf, what));
        }
        slots[static_cast<std::size_t>(feature)] = true;
      }
    }
  };
  check_landmarks(c.points, false);
  check_landmarks(c.lines, true);
  for (const auto& k : c.keyframes) {
    if (k.parent >= 0 && !index.count(k.parent)) fail(fmt::format("keyframe {}: unknown parent {}", k.id, k.parent));
    for (const auto& [id, w] : k.covisibility) {
      if (!index.count(id)) fail(fmt::format("keyframe {}: covisible with unknown keyframe {}", k.id, id));
    }
    for (long id : k.loop_edges) {
      if (!index.count(id)) fail(fmt::format("keyframe {}: loop edge to unknown keyframe {}", k.id, id));
    }
    if (k.imu && k.imu->previous >= 0) {
      // The chain runs forward in time, one successor per keyframe (checked below), over the
      // interval between the two keyframes.
      const auto prev = index.find(k.imu->previous);
      if (prev == index.end()) fail(fmt::format("keyframe {}: IMU predecessor {} unknown", k.id, k.imu->previous));
      const auto& before = c.keyframes[prev->second];
      if (!before.imu) fail(fmt::format("keyframe {}: IMU predecessor {} has no IMU state", k.id, before.id));
      const auto& pim = *k.imu->from_previous;
      if (std::abs(pim.t_i() - before.data->timestamp) > kImuTimeTolerance ||
          std::abs(pim.t_j() - k.data->timestamp) > kImuTimeTolerance || !(before.data->timestamp < k.data->timestamp)) {
        fail(fmt::format("keyframe {}: IMU interval [{:.6f}, {:.6f}] is not the one from keyframe {} ({:.6f}) to it ({:.6f})",
                         k.id, pim.t_i(), pim.t_j(), before.id, before.data->timestamp, k.data->timestamp));
      }
    }
    // Walking up must reach a root within as many steps as there are keyframes.
    long at = k.parent;
    for (std::size_t steps = 0; at >= 0; ++steps) {
      if (steps > c.keyframes.size() || at == k.id) fail(fmt::format("keyframe {}: the spanning tree has a cycle", k.id));
      at = c.keyframes[index.at(at)].parent;
    }
  }
  std::set<long> predecessors;
  for (const auto& k : c.keyframes) {
    if (k.imu && k.imu->previous >= 0 && !predecessors.insert(k.imu->previous).second) {
      fail(fmt::format("keyframe {} is the IMU predecessor of two keyframes", k.imu->previous));
    }
  }
}

}  // namespace

MapContents capture_map(const map::Map& map, const place::KeyframeDatabase* database, MapFileMeta meta) {
  const auto hold = map.hold_objects();  // nothing is freed while the map is read
  MapContents c;
  c.meta = std::move(meta);
  c.meta.version = kMapFileVersion;
  c.meta.next_ids = map.next_ids();
  // A new map segment no loop tied to the map lies where a guess put it: a map file holds only the
  // map's own frame (a loaded map is all anchored, so a guessed part would localize as trusted).
  std::vector<map::KeyFrame*> keyframes;
  std::size_t unanchored = 0;
  for (auto* kf : map.keyframes()) {
    if (map.anchored(kf->segment())) {
      keyframes.push_back(kf);
    } else {
      ++unanchored;
    }
  }
  if (unanchored > 0) {
    spdlog::warn("map file: {} keyframes of map segments not tied to the map left out (and the points and lines "
                 "only they observe)",
                 unanchored);
  }
  std::set<long> saved;
  for (const auto* kf : keyframes) saved.insert(kf->id());
  auto known = [&](const map::KeyFrame* kf) { return kf && saved.count(kf->id()) > 0; };
  for (const auto* kf : keyframes) {
    SavedKeyframe k;
    k.id = kf->id();
    k.data = kf->shared_data();
    k.T_cw = kf->pose();
    if (database) k.place = database->description(kf);
    k.parent = known(kf->parent()) ? kf->parent()->id() : -1;
    for (auto* other : kf->covisibles()) {
      if (known(other)) k.covisibility.emplace_back(other->id(), kf->weight(other));
    }
    std::sort(k.covisibility.begin(), k.covisibility.end());
    for (auto* other : kf->loop_edges()) {
      if (known(other)) k.loop_edges.push_back(other->id());
    }
    if (const auto imu = kf->imu()) {
      SavedImuState s{imu->v, imu->bias, imu->estimated, -1, nullptr};
      // A predecessor left out (culled meanwhile, or in another segment) starts the chain here.
      if (known(imu->previous) && imu->from_previous) {
        s.previous = imu->previous->id();
        s.from_previous = imu->from_previous;
      }
      k.imu = s;
    }
    c.keyframes.push_back(std::move(k));
  }
  std::size_t inconsistent = 0;
  auto capture = [&](const auto* landmark, SavedLandmark& l) {
    using Landmark = std::remove_cv_t<std::remove_pointer_t<decltype(landmark)>>;
    l.id = landmark->id();
    l.created_frame = landmark->created_frame();
    for (const auto& [kf, index] : landmark->observation_list()) {
      if (!known(kf)) continue;
      // The keyframe's slot decides: an observation whose slot holds another landmark (or none)
      // is not what tracking and matching see, and would make the file inconsistent.
      if (Landmark::slot(*kf, index) != landmark) {
        ++inconsistent;
        continue;
      }
      l.observations.emplace_back(kf->id(), index);
    }
    const auto* ref = landmark->reference();
    l.reference = known(ref) ? ref->id() : (l.observations.empty() ? -1 : l.observations.front().first);
    l.state = landmark->saved_state();
  };
  for (const auto* p : map.points()) {
    SavedLandmark l;
    capture(p, l);
    if (l.reference < 0) continue;  // observed by no saved keyframe
    l.a = p->position();
    l.level0_max_distance = p->level0_max_distance();
    c.points.push_back(std::move(l));
  }
  for (const auto* ml : map.lines()) {
    SavedLandmark l;
    capture(ml, l);
    if (l.reference < 0) continue;
    l.a = ml->start();
    l.b = ml->end();
    c.lines.push_back(std::move(l));
  }
  if (inconsistent > 0) {
    spdlog::debug("map file: {} observations left out, their keyframe slot holds another landmark", inconsistent);
  }
  return c;
}

std::string map_to_bytes(const MapContents& c) {
  std::vector<std::string> payloads;
  {
    Writer w;
    write_meta(w, c.meta);
    payloads.push_back(std::move(w.str()));
  }
  {
    Writer w;
    w.put_count(c.keyframes.size());
    for (const auto& k : c.keyframes) write_keyframe(w, k);
    payloads.push_back(std::move(w.str()));
  }
  for (const auto* set : {&c.points, &c.lines}) {
    Writer w;
    w.put_count(set->size());
    for (const auto& l : *set) write_landmark(w, l, set == &c.lines);
    payloads.push_back(std::move(w.str()));
  }
  {
    Writer w;
    w.put_count(c.keyframes.size());
    for (const auto& k : c.keyframes) write_graph(w, k);
    payloads.push_back(std::move(w.str()));
  }
  {
    Writer w;
    w.put<std::uint8_t>(c.meta.gravity_aligned);
    std::size_t states = 0;
    for (const auto& k : c.keyframes) states += k.imu.has_value();
    w.put_count(states);
    for (const auto& k : c.keyframes) {
      if (k.imu) write_imu_state(w, k.id, *k.imu);
    }
    payloads.push_back(std::move(w.str()));
  }
  Writer out;
  out.put_bytes(kMagic, sizeof(kMagic));
  out.put<std::uint32_t>(kMapFileVersion);
  out.put<std::uint32_t>(static_cast<std::uint32_t>(payloads.size()));
  for (std::size_t i = 0; i < payloads.size(); ++i) {
    out.put_bytes(kSectionTags[i], 4);
    out.put<std::uint64_t>(payloads[i].size());
    out.put<std::uint64_t>(word_fnv1a(payloads[i].data(), payloads[i].size()));
    out.str() += payloads[i];
  }
  return std::move(out.str());
}

MapContents map_from_bytes(std::string_view bytes, const std::string& source, const MapReadOptions& options) {
  if (bytes.size() < 16 || std::memcmp(bytes.data(), kMagic, sizeof(kMagic)) != 0) {
    throw InputError(source, "not a plslam map (no 'plslmap' magic)");
  }
  std::uint32_t version, sections;
  std::memcpy(&version, bytes.data() + 8, 4);
  std::memcpy(&sections, bytes.data() + 12, 4);
  if (version != 1 && version != kMapFileVersion) {
    throw InputError(source, fmt::format("map format version {} (this plslam reads 1 to {})", version, kMapFileVersion));
  }
  const std::uint32_t expected_sections = version == 1 ? kVersion1Sections : kVersion1Sections + 1;
  if (sections != expected_sections) {
    throw InputError(source, fmt::format("{} sections (expected {} in version {})", sections, expected_sections, version));
  }
  std::size_t at = 16;
  std::vector<Reader> readers;
  for (std::uint32_t i = 0; i < sections; ++i) {
    if (bytes.size() - at < 20) throw InputError(source, fmt::format("truncated before section {}", kSectionTags[i]));
    if (std::memcmp(bytes.data() + at, kSectionTags[i], 4) != 0) {
      throw InputError(source, fmt::format("expected section {} at byte {}", kSectionTags[i], at));
    }
    std::uint64_t size, checksum;
    std::memcpy(&size, bytes.data() + at + 4, 8);
    std::memcpy(&checksum, bytes.data() + at + 12, 8);
    at += 20;
    if (size > bytes.size() - at) {
      throw InputError(source, fmt::format("section {}: {} bytes announced, {} left (truncated?)", kSectionTags[i],
                                           size, bytes.size() - at));
    }
    const char* payload = bytes.data() + at;
    if (options.verify_checksums && word_fnv1a(payload, static_cast<std::size_t>(size)) != checksum) {
      throw InputError(source, fmt::format("section {}: checksum mismatch (corrupt file)", kSectionTags[i]));
    }
    readers.emplace_back(payload, static_cast<std::size_t>(size), source, kSectionTags[i]);
    at += static_cast<std::size_t>(size);
  }
  if (at != bytes.size()) throw InputError(source, fmt::format("{} bytes after the last section", bytes.size() - at));

  MapContents c;
  c.meta = read_meta(readers[0]);
  c.meta.version = version;
  // The keyframes and the landmarks are independent sections: read side by side (about half the
  // time of a load each on the rendered loops).
  auto landmarks = std::async(std::launch::async, [&] {
    for (int s = 2; s <= 3; ++s) {
      Reader& r = readers[static_cast<std::size_t>(s)];
      const bool line = s == 3;
      auto& set = line ? c.lines : c.points;
      const std::size_t n = r.count(100);
      set.reserve(n);
      for (std::size_t i = 0; i < n; ++i) {
        set.push_back(read_landmark(r, line, line ? c.meta.next_ids.line : c.meta.next_ids.point));
      }
    }
  });
  try {
    Reader& r = readers[1];
    const std::size_t n = r.count(100);
    c.keyframes.reserve(n);
    for (std::size_t i = 0; i < n; ++i) {
      c.keyframes.push_back(read_keyframe(r, c.meta));
      if (i > 0 && c.keyframes[i].id <= c.keyframes[i - 1].id) r.fail("keyframe ids not increasing");
    }
  } catch (...) {
    landmarks.wait();  // it reads `c` and `readers`: never leave it running
    throw;
  }
  landmarks.get();  // rethrows its InputError
  {
    Reader& r = readers[4];
    if (r.count(20) != c.keyframes.size()) r.fail("not one entry per keyframe");
    for (auto& k : c.keyframes) read_graph(r, k);
  }
  if (version > 1) {
    Reader& r = readers[5];
    const auto aligned = r.get<std::uint8_t>();
    if (aligned > 1) r.fail("bad gravity flag");
    c.meta.gravity_aligned = aligned == 1;
    const std::size_t n = r.count(8 + 9 * 8 + 1 + 8);
    if (n > c.keyframes.size()) r.fail("more IMU states than keyframes");
    std::size_t at = 0;  // states come by increasing keyframe id, as the keyframes
    for (std::size_t i = 0; i < n; ++i) {
      auto [id, state] = read_imu_state(r);
      while (at < c.keyframes.size() && c.keyframes[at].id < id) ++at;
      if (at == c.keyframes.size() || c.keyframes[at].id != id) r.fail(fmt::format("IMU state of unknown keyframe {} (or out of order)", id));
      c.keyframes[at++].imu = std::move(state);
    }
  }
  for (auto& r : readers) {
    if (!r.done()) r.fail(fmt::format("{} bytes left after its records", r.left()));
  }
  check_references(c, source);
  return c;
}

void restore_map(const MapContents& c, map::Map& map, place::KeyframeDatabase* database) {
  if (database && c.meta.vocabulary_checksum != 0 && c.meta.vocabulary_checksum != database->vocabulary().checksum()) {
    throw std::invalid_argument("restore_map: the map's words come from another vocabulary");
  }
  std::unordered_map<long, map::KeyFrame*> kfs;
  for (const auto& k : c.keyframes) {
    kfs[k.id] = map.restore_keyframe(k.id, k.data, k.T_cw);
  }
  for (const auto& l : c.points) {
    auto* p = map.restore_point(l.id, l.a, kfs.at(l.reference), l.created_frame);
    for (const auto& [kf, index] : l.observations) {
      kfs.at(kf)->add_map_point(p, index);
      p->add_observation(kfs.at(kf), index);
    }
    p->restore_state(l.state);
    p->restore_level0_max_distance(l.level0_max_distance);
  }
  for (const auto& l : c.lines) {
    auto* ml = map.restore_line(l.id, l.a, l.b, kfs.at(l.reference), l.created_frame);
    for (const auto& [kf, index] : l.observations) {
      kfs.at(kf)->add_map_line(ml, index);
      ml->add_observation(kfs.at(kf), index);
    }
    ml->restore_state(l.state);
  }
  // By increasing id: a predecessor's state is set before its successor's (set_imu links the two).
  for (const auto& k : c.keyframes) {
    if (!k.imu) continue;
    map::KeyFrameImu imu{k.imu->v, k.imu->bias, nullptr, nullptr, k.imu->estimated};
    if (k.imu->previous >= 0) {
      imu.previous = kfs.at(k.imu->previous);
      imu.from_previous = k.imu->from_previous;
    }
    kfs.at(k.id)->set_imu(imu);
  }
  for (const auto& k : c.keyframes) {
    map::IdMap<map::KeyFrame, int> weights;
    for (const auto& [id, w] : k.covisibility) weights.emplace(kfs.at(id), w);
    map::IdSet<map::KeyFrame> loops;
    for (long id : k.loop_edges) loops.insert(kfs.at(id));
    kfs.at(k.id)->restore_graph(k.parent >= 0 ? kfs.at(k.parent) : nullptr, weights, loops);
    if (!database) continue;
    if (k.place && c.meta.vocabulary_checksum != 0) {
      database->add(kfs.at(k.id), k.place);
    } else {
      database->add(kfs.at(k.id));  // made without a vocabulary: described now
    }
  }
  map.restore_next_ids(c.meta.next_ids);
}

void check_map_matches(const MapFileMeta& meta, const StereoCalibration& calib, const place::Vocabulary* vocabulary,
                       const std::string& source) {
  const auto& m = meta.calib;
  auto close = [](double a, double b) { return std::abs(a - b) <= 1e-4 * std::max(std::abs(a), std::abs(b)); };
  if (m.width != calib.width || m.height != calib.height) {
    throw InputError(source, fmt::format("map made for {}x{} images, the dataset has {}x{}", m.width, m.height,
                                         calib.width, calib.height));
  }
  if (!close(m.baseline, calib.baseline)) {
    throw InputError(source, fmt::format("map made with a {:.6g} m baseline, the dataset has {:.6g} m", m.baseline,
                                         calib.baseline));
  }
  if (!close(m.fx, calib.fx) || !close(m.fy, calib.fy) || !close(m.cx, calib.cx) || !close(m.cy, calib.cy)) {
    throw InputError(source, fmt::format("map made with intrinsics fx {:.6g} fy {:.6g} cx {:.6g} cy {:.6g}, the "
                                         "dataset has {:.6g} {:.6g} {:.6g} {:.6g}",
                                         m.fx, m.fy, m.cx, m.cy, calib.fx, calib.fy, calib.cx, calib.cy));
  }
  if (!vocabulary) {
    throw InputError(source, "finding the camera in a map needs place recognition (a vocabulary); it is off");
  }
  if (meta.vocabulary_checksum != 0 && meta.vocabulary_checksum != vocabulary->checksum()) {
    throw InputError(source, fmt::format("map made with vocabulary {:016x} ({} words), this run uses {:016x} ({} words)",
                                         meta.vocabulary_checksum, meta.vocabulary_words, vocabulary->checksum(),
                                         vocabulary->size()));
  }
}

void save_map_file(const std::filesystem::path& path, const MapContents& contents) {
  const std::string bytes = map_to_bytes(contents);
  io::write_file_atomically(path, [&](std::ostream& o) { o.write(bytes.data(), static_cast<std::streamsize>(bytes.size())); });
}

MapContents load_map_file(const std::filesystem::path& path) {
  // Opened the checked way first: a missing file or a folder gets the usual one-line error.
  { std::ifstream probe = open_input_file(path, "map file not found"); }
  const int fd = ::open(path.c_str(), O_RDONLY | O_CLOEXEC);
  if (fd < 0) throw InputError(path.string(), std::string("cannot open: ") + std::strerror(errno));
  struct stat st {};
  if (::fstat(fd, &st) != 0 || st.st_size < 0) {
    ::close(fd);
    throw InputError(path.string(), "cannot read the map file");
  }
  const auto size = static_cast<std::size_t>(st.st_size);
  if (size == 0) {
    ::close(fd);
    return map_from_bytes({}, path.string());  // the usual "not a plslam map"
  }
  void* p = ::mmap(nullptr, size, PROT_READ, MAP_PRIVATE | MAP_POPULATE, fd, 0);
  ::close(fd);
  if (p == MAP_FAILED) throw InputError(path.string(), std::string("cannot map the file: ") + std::strerror(errno));
  struct Unmap {
    void* p;
    std::size_t n;
    ~Unmap() { ::munmap(p, n); }
  } unmap{p, size};
  return map_from_bytes(std::string_view(static_cast<const char*>(p), size), path.string());
}

}  // namespace plslam::system
