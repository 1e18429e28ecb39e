#pragma once
// A synthetic world: textured planar quads (boxes are six quads), point lights, and the
// straight 3D edges that form the ground truth. World frame: metres, z up, floor at z = 0.
#include <cstdint>
#include <string>
#include <vector>

#include <Eigen/Core>
#include <Eigen/Geometry>

#include "plslam/synth/texture.h"

namespace plslam::synth {

// A parallelogram: points origin + s*u + t*v for s, t in [0, 1]. Its front side is the side
// u x v points to; only the front is rendered (back faces are culled).
struct Quad {
  Eigen::Vector3d origin, u, v;
  int texture = 0;
  // Texture repeats across the quad (texture coordinates reach s*repeat_u, t*repeat_v).
  float repeat_u = 1, repeat_v = 1;
  float emission = 0;  // > 0 for lamps: adds light independent of illumination
  // Illumination at a grid of points over the quad (row-major, grid_u x grid_v), filled by
  // Scene::bake_lighting; the renderer interpolates it bilinearly.
  int grid_u = 2, grid_v = 2;
  std::vector<float> light;
  Eigen::Vector3d normal() const { return u.cross(v).normalized(); }
};

struct PointLight {
  Eigen::Vector3d position;
  double power = 1;   // irradiance at 1 m on a facing surface
  double range = 4;   // soft falloff distance
};

struct Segment3d {
  Eigen::Vector3d a, b;
};

enum class SceneKind { kOffice, kCorridor, kStreet, kCalibration };

const char* to_string(SceneKind s);
SceneKind parse_scene_kind(const std::string& name);  // office|corridor|street|calibration; InputError else

struct Scene {
  SceneKind kind = SceneKind::kOffice;
  std::vector<Texture> textures;
  std::vector<Quad> quads;
  std::vector<PointLight> lights;
  double ambient = 0.3;
  Eigen::Vector3d sun_direction = Eigen::Vector3d::Zero();  // towards the sun; zero: indoor
  double sun_power = 0;
  float background = 0.8f;  // radiance where nothing is hit (sky)
  // Closed loop the camera follows (z is the camera height), and the nominal speed on it.
  std::vector<Eigen::Vector2d> path;
  double camera_height = 1.5;
  double nominal_speed = 1.0;
  double max_speed = 1.5;
  bool vehicle = false;  // car motion (no bobbing, no pitch/roll wobble)
  double look_around = 0.22;  // amplitude (rad) of the walker's slow yaw away from the path

  int add_texture(Texture t);
  // Adds a quad with texture repeats derived from the physical size and `texel_m` metres per
  // texture tile (0: stretch the texture once over the quad).
  int add_quad(const Eigen::Vector3d& origin, const Eigen::Vector3d& u, const Eigen::Vector3d& v,
               int texture, double tile_m = 0, float emission = 0);
  // An axis-aligned box [lo, hi] with the given texture on its sides and top.
  void add_box(const Eigen::Vector3d& lo, const Eigen::Vector3d& hi, int side_texture, int top_texture,
               double tile_m = 0, bool with_bottom = false);
  // Computes the lighting grids of every quad from the lights (call after adding everything).
  void bake_lighting();

  // Ground truth: every quad edge once (shared box edges are merged).
  std::vector<Segment3d> edges() const;
  // Sample points on the surfaces: quad corners plus `per_quad` deterministic interior points.
  std::vector<Eigen::Vector3d> sample_points(int per_quad, std::uint64_t seed) const;
};

Scene build_scene(SceneKind kind, std::uint64_t seed);

}  // namespace plslam::synth
