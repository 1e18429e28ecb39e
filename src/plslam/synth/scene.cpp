#include "plslam/synth/scene.h"

#include <algorithm>
#include <cmath>
#include <map>
#include <tuple>

#include "plslam/core/error.h"

namespace plslam::synth {

const char* to_string(SceneKind s) {
  switch (s) {
    case SceneKind::kOffice: return "office";
    case SceneKind::kCorridor: return "corridor";
    case SceneKind::kStreet: return "street";
    case SceneKind::kCalibration: return "calibration";
  }
  return "?";
}

SceneKind parse_scene_kind(const std::string& name) {
  if (name == "office") return SceneKind::kOffice;
  if (name == "corridor") return SceneKind::kCorridor;
  if (name == "street") return SceneKind::kStreet;
  if (name == "calibration") return SceneKind::kCalibration;
  throw InputError("", "unknown scene '" + name + "' (expected office, corridor, street or calibration)");
}

int Scene::add_texture(Texture t) {
  textures.push_back(std::move(t));
  return static_cast<int>(textures.size()) - 1;
}

int Scene::add_quad(const Eigen::Vector3d& origin, const Eigen::Vector3d& u, const Eigen::Vector3d& v,
                    int texture, double tile_m, float emission) {
  Quad q;
  q.origin = origin;
  q.u = u;
  q.v = v;
  q.texture = texture;
  q.emission = emission;
  if (tile_m > 0) {
    q.repeat_u = static_cast<float>(u.norm() / tile_m);
    q.repeat_v = static_cast<float>(v.norm() / tile_m);
  }
  quads.push_back(std::move(q));
  return static_cast<int>(quads.size()) - 1;
}

void Scene::add_box(const Eigen::Vector3d& lo, const Eigen::Vector3d& hi, int side_texture, int top_texture,
                    double tile_m, bool with_bottom) {
  const Eigen::Vector3d d = hi - lo;
  const Eigen::Vector3d down(0, 0, -d.z());
  // Adds a face whose front points along `n`; flips u (keeping v) when needed so textures stay
  // upright and unmirrored as seen from outside.
  auto face = [&](Eigen::Vector3d o, Eigen::Vector3d u, const Eigen::Vector3d& v, const Eigen::Vector3d& n, int tex) {
    if (u.cross(v).dot(n) < 0) {
      o += u;
      u = -u;
    }
    add_quad(o, u, v, tex, tile_m);
  };
  const Eigen::Vector3d top_lo(lo.x(), lo.y(), hi.z());
  face(top_lo, {d.x(), 0, 0}, down, {0, -1, 0}, side_texture);
  face(top_lo + Eigen::Vector3d(0, d.y(), 0), {d.x(), 0, 0}, down, {0, 1, 0}, side_texture);
  face(top_lo, {0, d.y(), 0}, down, {-1, 0, 0}, side_texture);
  face(top_lo + Eigen::Vector3d(d.x(), 0, 0), {0, d.y(), 0}, down, {1, 0, 0}, side_texture);
  face(top_lo, {d.x(), 0, 0}, {0, d.y(), 0}, {0, 0, 1}, top_texture);
  if (with_bottom) face(lo, {d.x(), 0, 0}, {0, d.y(), 0}, {0, 0, -1}, top_texture);
}

void Scene::bake_lighting() {
  for (Quad& q : quads) {
    q.grid_u = std::clamp(static_cast<int>(std::ceil(q.u.norm() / 1.0)) + 1, 2, 24);
    q.grid_v = std::clamp(static_cast<int>(std::ceil(q.v.norm() / 1.0)) + 1, 2, 24);
    const Eigen::Vector3d n = q.normal();
    q.light.resize(static_cast<std::size_t>(q.grid_u) * q.grid_v);
    for (int j = 0; j < q.grid_v; ++j)
      for (int i = 0; i < q.grid_u; ++i) {
        const Eigen::Vector3d p =
            q.origin + q.u * (double(i) / (q.grid_u - 1)) + q.v * (double(j) / (q.grid_v - 1));
        double e = ambient * (0.8 + 0.2 * std::abs(n.z()));
        for (const PointLight& l : lights) {
          const Eigen::Vector3d to = l.position - p;
          const double dist = to.norm();
          const double c = std::max(0.0, n.dot(to) / std::max(dist, 1e-6));
          e += l.power * c / (1 + (dist / l.range) * (dist / l.range));
        }
        if (sun_power > 0) e += sun_power * std::max(0.0, n.dot(sun_direction));
        q.light[static_cast<std::size_t>(j) * q.grid_u + i] = static_cast<float>(e + q.emission);
      }
  }
}

std::vector<Segment3d> Scene::edges() const {
  std::vector<Segment3d> out;
  std::map<std::tuple<long, long, long, long, long, long>, bool> seen;
  auto key = [](const Eigen::Vector3d& p) {
    return std::make_tuple(std::lround(p.x() * 1e4), std::lround(p.y() * 1e4), std::lround(p.z() * 1e4));
  };
  for (const Quad& q : quads) {
    const Eigen::Vector3d c[4] = {q.origin, q.origin + q.u, q.origin + q.u + q.v, q.origin + q.v};
    for (int k = 0; k < 4; ++k) {
      auto ka = key(c[k]), kb = key(c[(k + 1) % 4]);
      if (kb < ka) std::swap(ka, kb);
      const auto k6 = std::tuple_cat(ka, kb);
      if (seen.emplace(k6, true).second) out.push_back({c[k], c[(k + 1) % 4]});
    }
  }
  return out;
}

std::vector<Eigen::Vector3d> Scene::sample_points(int per_quad, std::uint64_t seed) const {
  std::vector<Eigen::Vector3d> out;
  Rng rng(seed);
  for (const Quad& q : quads) {
    out.push_back(q.origin);
    out.push_back(q.origin + q.u);
    out.push_back(q.origin + q.v);
    out.push_back(q.origin + q.u + q.v);
    for (int k = 0; k < per_quad; ++k) out.push_back(q.origin + q.u * rng.uniform() + q.v * rng.uniform());
  }
  return out;
}

}  // namespace plslam::synth
