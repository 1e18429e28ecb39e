// The three built-in worlds. Layouts are fixed (so ground truth and loops are predictable);
// the seed varies textures, poster designs, book spines and small placement details.
#include <algorithm>
#include <cmath>

#include "plslam/synth/scene.h"
#include "plslam/synth/calibration_scene.h"

namespace plslam::synth {

namespace {

using V3 = Eigen::Vector3d;
using V2 = Eigen::Vector2d;

// Vertical rectangle on the segment a->b (seen from above) between heights z0 and z1, facing
// the left side of a->b, pushed `offset` metres along its normal.
int vquad(Scene& s, V2 a, V2 b, double z0, double z1, int tex, double tile = 0, double offset = 0,
          float emission = 0) {
  const V2 d = b - a;
  const V2 n = V2(-d.y(), d.x()).normalized() * offset;
  return s.add_quad(V3(a.x() + n.x(), a.y() + n.y(), z1), V3(d.x(), d.y(), 0), V3(0, 0, z0 - z1), tex, tile,
                    emission);
}

// Box spanning along a wall from a to b (axis-aligned), `depth` deep towards the left of a->b.
void wall_box(Scene& s, V2 a, V2 b, double z0, double z1, double depth, int side, int top, double tile = 0) {
  const V2 d = b - a;
  const V2 n = V2(-d.y(), d.x()).normalized() * depth;
  const V2 c = a + n, e = b + n;
  const V3 lo(std::min({a.x(), b.x(), c.x(), e.x()}), std::min({a.y(), b.y(), c.y(), e.y()}), z0);
  const V3 hi(std::max({a.x(), b.x(), c.x(), e.x()}), std::max({a.y(), b.y(), c.y(), e.y()}), z1);
  s.add_box(lo, hi, side, top, tile);
}

// A door in the wall a->b (facing left of it) centred at fraction f: leaf plus a frame.
void door(Scene& s, V2 a, V2 b, double at, int leaf, int frame) {
  const V2 dir = (b - a).normalized();
  const V2 c = a + dir * at;
  const V2 l = c - dir * 0.45, r = c + dir * 0.45;
  vquad(s, l, r, 0.0, 2.05, leaf, 0, 0.006);
  wall_box(s, l - dir * 0.07, l, 0.0, 2.12, 0.03, frame, frame);
  wall_box(s, r, r + dir * 0.07, 0.0, 2.12, 0.03, frame, frame);
  wall_box(s, l, r, 2.05, 2.12, 0.03, frame, frame);
  const V2 h = r - dir * 0.12;  // handle
  wall_box(s, h - dir * 0.12, h, 1.0, 1.04, 0.06, frame, frame);
}

// Dense control polygon for a closed path around a rectangle (counter-clockwise), with corners
// rounded to `radius` metres so that the B-spline's curvature, and with it the yaw rate, stays
// bounded. Starts in the middle of the first straight, so the first frames are not in a turn.
std::vector<V2> rounded_rect(V2 lo, V2 hi, double radius) {
  const V2 c[4] = {lo, V2(hi.x(), lo.y()), hi, V2(lo.x(), hi.y())};
  std::vector<V2> out;
  for (int k = 0; k < 4; ++k) {
    const V2 p = c[k], n = c[(k + 1) % 4], next = c[(k + 2) % 4];
    const V2 d = (n - p).normalized(), dout = (next - n).normalized();
    const double len = (n - p).norm();
    const int steps = std::max(2, static_cast<int>(std::ceil((len - 2 * radius) / std::max(0.5, radius / 2))));
    for (int i = 0; i < steps; ++i) out.push_back(p + d * (radius + (len - 2 * radius) * i / steps));
    const V2 centre = n - d * radius + dout * radius;
    constexpr int kArc = 9;  // 10 degrees per control point
    for (int j = 0; j < kArc; ++j) {
      const double th = 1.5707963267948966 * j / kArc;
      out.push_back(centre + radius * (-dout * std::cos(th) + d * std::sin(th)));
    }
  }
  // Begin in the middle of the first straight.
  const std::size_t first_straight = static_cast<std::size_t>(
      std::max(2, static_cast<int>(std::ceil(((c[1] - c[0]).norm() - 2 * radius) / std::max(0.5, radius / 2)))));
  std::rotate(out.begin(), out.begin() + first_straight / 2, out.end());
  return out;
}

Scene office(std::uint64_t seed) {
  Scene s;
  s.kind = SceneKind::kOffice;
  Rng rng(seed ^ 0x0FF1CE);
  const double X = 16, Y = 10, Z = 3;
  const int paint = s.add_texture(make_uniform(0.72f, 0.025f, seed + 1));
  const int paint2 = s.add_texture(make_uniform(0.55f, 0.025f, seed + 2));
  const int floor = s.add_texture(make_tiles(512, seed + 3, 8, 0.42f, 0.12f));
  const int ceiling = s.add_texture(make_tiles(256, seed + 4, 4, 0.82f, 0.02f));
  const int wood = s.add_texture(make_wood(512, seed + 5, 0.55f));
  const int books = s.add_texture(make_books(512, seed + 6));
  const int bricks = s.add_texture(make_bricks(512, seed + 7, 0.42f, 0.72f));
  const int dark = s.add_texture(make_uniform(0.18f, 0.02f, seed + 8));
  const int lamp = s.add_texture(make_uniform(0.95f, 0.0f, seed + 9));
  const int concrete = s.add_texture(make_noise(256, seed + 10, 0.6f, 0.1f, 8));
  const int door_tex = s.add_texture(make_wood(256, seed + 11, 0.38f));
  const int steel = s.add_texture(make_noise(128, seed + 12, 0.35f, 0.04f, 4));
  const int outside = s.add_texture(make_facade(256, seed + 13, 3, 3));
  const int cork = s.add_texture(make_noise(256, seed + 14, 0.5f, 0.12f, 32));
  const int drawers = s.add_texture(make_tiles(64, seed + 15, 1, 0.5f, 0.0f));
  const int radiator = s.add_texture(make_stripes(64, 8, 0.75f, 0.45f));
  std::vector<int> posters, pages;
  for (int k = 0; k < 8; ++k) posters.push_back(s.add_texture(make_poster(256, seed * 31 + 100 + k)));
  for (int k = 0; k < 4; ++k) pages.push_back(s.add_texture(make_text_page(512, seed * 31 + 200 + k)));

  const V2 sw(0, 0), se(X, 0), ne(X, Y), nw(0, Y);
  // Room shell (fronts face inwards).
  vquad(s, sw, se, 0, Z, paint, 0);
  vquad(s, se, ne, 0, Z, bricks, 2.0);
  vquad(s, ne, nw, 0, Z, paint, 0);
  vquad(s, nw, sw, 0, Z, paint2, 0);
  s.add_quad(V3(0, 0, 0), V3(X, 0, 0), V3(0, Y, 0), floor, 4.0);
  s.add_quad(V3(0, 0, Z), V3(0, Y, 0), V3(X, 0, 0), ceiling, 2.4);
  // Skirting along every wall.
  vquad(s, sw, se, 0, 0.09, dark, 0, 0.01);
  vquad(s, se, ne, 0, 0.09, dark, 0, 0.01);
  vquad(s, ne, nw, 0, 0.09, dark, 0, 0.01);
  vquad(s, nw, sw, 0, 0.09, dark, 0, 0.01);

  // South wall: windows (bright panels with frames) above desks.
  for (int k = 0; k < 3; ++k) {
    const double x0 = 2.0 + k * 5.0;
    vquad(s, V2(x0, 0), V2(x0 + 2.4, 0), 1.0, 2.4, outside, 3.0, 0.004, 1.3f);
    wall_box(s, V2(x0 + 0.3, 0), V2(x0 + 2.1, 0), 0.15, 0.65, 0.08, radiator, paint, 0.5);
    wall_box(s, V2(x0 - 0.06, 0), V2(x0 + 2.46, 0), 0.94, 1.0, 0.12, paint, paint);
    wall_box(s, V2(x0 + 1.17, 0), V2(x0 + 1.23, 0), 1.0, 2.4, 0.05, paint, paint);
    wall_box(s, V2(x0 - 0.06, 0), V2(x0 + 2.46, 0), 2.4, 2.46, 0.05, paint, paint);
  }
  // Notice boards with pinned pages between the windows.
  for (double x0 : {4.9, 9.9}) {
    wall_box(s, V2(x0, 0), V2(x0 + 1.6, 0), 1.1, 2.1, 0.02, cork, wood);
    for (int k = 0; k < 6; ++k) {
      const double px = x0 + 0.08 + (k % 3) * 0.5 + rng.uniform(-0.03, 0.03);
      const double pz = 1.17 + (k / 3) * 0.45 + rng.uniform(-0.03, 0.03);
      vquad(s, V2(px, 0), V2(px + 0.3, 0), pz, pz + 0.38, k % 2 ? pages[k % 4] : posters[k], 0, 0.022);
    }
  }
  // Desks with monitors and papers along the south and north walls.
  auto desk = [&](V2 a, V2 b) {
    wall_box(s, a, b, 0.72, 0.76, 0.75, wood, wood, 1.2);
    const V2 d = (b - a).normalized(), n(-d.y(), d.x());
    for (double f : {0.05, 0.95}) {
      const V2 p = a + (b - a) * f;
      wall_box(s, p, p + d * 0.05, 0, 0.72, 0.7, steel, steel);
      (void)n;
    }
    const V2 m = a + (b - a) * rng.uniform(0.3, 0.6) + n * 0.15;
    wall_box(s, m, m + d * 0.55, 0.8, 1.15, 0.04, dark, dark);  // monitor
    wall_box(s, m + d * 0.25, m + d * 0.3, 0.76, 0.8, 0.04, steel, steel);
    // An office chair in front of the desk and a drawer unit beside it.
    const V2 c = a + (b - a) * rng.uniform(0.35, 0.65) + n * 1.0;
    s.add_box(V3(c.x() - 0.25, c.y() - 0.25, 0.42), V3(c.x() + 0.25, c.y() + 0.25, 0.5), dark, steel);
    s.add_box(V3(c.x() - 0.03, c.y() - 0.03, 0.05), V3(c.x() + 0.03, c.y() + 0.03, 0.42), steel, steel);
    s.add_box(V3(c.x() - 0.3, c.y() - 0.3, 0.0), V3(c.x() + 0.3, c.y() + 0.3, 0.05), dark, dark);
    const V2 back = c + n * 0.22;
    s.add_box(V3(std::min(back.x(), back.x() + n.x() * 0.06) - std::abs(d.x()) * 0.22,
                 std::min(back.y(), back.y() + n.y() * 0.06) - std::abs(d.y()) * 0.22, 0.55),
              V3(std::max(back.x(), back.x() + n.x() * 0.06) + std::abs(d.x()) * 0.22,
                 std::max(back.y(), back.y() + n.y() * 0.06) + std::abs(d.y()) * 0.22, 1.05),
              dark, dark);
    const V2 dr = b + d * 0.05;
    wall_box(s, dr, dr + d * 0.45, 0, 0.65, 0.6, drawers, steel);
    const V2 p = a + (b - a) * 0.15 + n * 0.35;
    s.add_quad(V3(p.x(), p.y(), 0.761), V3(d.x() * 0.3, d.y() * 0.3, 0), V3(n.x() * 0.21, n.y() * 0.21, 0),
               pages[rng.integer(0, 3)]);
  };
  desk(V2(1.6, 0), V2(4.8, 0));
  desk(V2(6.6, 0), V2(9.8, 0));
  desk(V2(11.6, 0), V2(14.8, 0));
  // North wall: two doors, shelves, posters.
  door(s, ne, nw, 2.0, door_tex, paint2);
  door(s, ne, nw, 11.0, door_tex, paint2);
  for (double x : {13.2, 9.5, 7.7}) {
    const V2 a(x, Y), b(x - 1.6, Y);
    wall_box(s, a, b, 0, 2.0, 0.4, wood, wood, 1.2);
    vquad(s, a + V2(0, -0.4), b + V2(0, -0.4), 0.05, 1.95, books, 0, 0.002);
  }
  for (double x : {4.6, 3.2}) vquad(s, V2(x, Y), V2(x - 1.0, Y), 1.2, 2.6, posters[static_cast<int>(x) % 8], 0, 0.004);
  // West wall: whiteboard with writing, posters, a door.
  vquad(s, V2(0, 8.6), V2(0, 5.8), 0.9, 2.1, pages[0], 0, 0.01);
  wall_box(s, V2(0, 8.65), V2(0, 5.75), 0.85, 0.9, 0.06, steel, steel);
  door(s, nw, sw, 6.0, door_tex, dark);
  vquad(s, V2(0, 3.0), V2(0, 2.0), 1.2, 2.5, posters[2], 0, 0.004);
  // Book shelves in the south-west corner (the walker faces this corner while turning).
  wall_box(s, V2(1.45, 0), V2(0.05, 0), 0, 2.0, -0.4, wood, wood, 1.2);
  vquad(s, V2(0.05, 0.4), V2(1.45, 0.4), 0.05, 1.95, books, 0, 0.002);
  wall_box(s, V2(0, 2.0), V2(0, 0.6), 0, 2.0, 0.4, wood, wood, 1.2);
  vquad(s, V2(0.4, 2.0), V2(0.4, 0.6), 0.05, 1.95, books, 0, 0.002);
  // East (brick) wall: posters and a tall cabinet.
  vquad(s, V2(X, 1.5), V2(X, 2.7), 1.1, 2.5, posters[4], 0, 0.004);
  vquad(s, V2(X, 6.8), V2(X, 8.2), 1.0, 2.3, posters[5], 0, 0.004);
  wall_box(s, V2(X, 3.8), V2(X, 5.6), 0, 2.1, 0.5, steel, steel);
  vquad(s, V2(X - 0.5, 3.8), V2(X - 0.5, 4.7), 0.1, 2.0, wood, 1.2, 0.002);
  vquad(s, V2(X - 0.5, 4.7), V2(X - 0.5, 5.6), 0.1, 2.0, wood, 1.2, 0.002);

  // Central island: pillars, back-to-back book shelves, a meeting table.
  s.add_box(V3(4.4, 4.8, 0), V3(4.8, 5.2, Z), concrete, concrete, 1.0);
  s.add_box(V3(11.2, 4.8, 0), V3(11.6, 5.2, Z), concrete, concrete, 1.0);
  s.add_box(V3(5.4, 4.6, 0), V3(10.6, 5.4, 1.8), wood, wood, 1.2);
  for (int k = 0; k < 3; ++k) {
    const double x0 = 5.5 + k * 1.7;
    vquad(s, V2(x0, 4.6), V2(x0 + 1.6, 4.6), 0.05, 1.75, books, 0, 0.002);
    vquad(s, V2(x0 + 1.6, 5.4), V2(x0, 5.4), 0.05, 1.75, books, 0, 0.002);
  }
  vquad(s, V2(10.6, 4.7), V2(10.6, 5.3), 1.0, 1.7, posters[6], 0, 0.004);
  vquad(s, V2(5.4, 5.3), V2(5.4, 4.7), 1.0, 1.7, posters[7], 0, 0.004);
  s.add_box(V3(6.5, 3.6, 0.72), V3(9.5, 4.2, 0.76), wood, wood, 1.2);
  s.add_box(V3(6.6, 3.7, 0), V3(6.7, 4.1, 0.72), steel, steel);
  s.add_box(V3(9.3, 3.7, 0), V3(9.4, 4.1, 0.72), steel, steel);
  s.add_box(V3(7.0, 6.0, 0), V3(9.0, 6.5, 0.9), steel, dark);  // low cabinet
  s.add_quad(V3(7.4, 6.1, 0.901), V3(0.3, 0, 0), V3(0, 0.21, 0), pages[1]);

  // Ceiling lamps (emissive panels) and the lights they cast.
  for (double x = 2.5; x < X; x += 3.5)
    for (double y = 2.0; y < Y; y += 3.0) {
      s.add_quad(V3(x - 0.3, y - 0.6, Z - 0.005), V3(0, 1.2, 0), V3(0.6, 0, 0), lamp, 0, 1.5f);
      s.lights.push_back({V3(x, y, Z - 0.3), 0.35, 3.0});
    }
  s.ambient = 0.35;
  s.background = 0.5f;
  s.path = rounded_rect(V2(2.4, 2.2), V2(13.6, 7.8), 1.4);
  s.camera_height = 1.45;
  s.nominal_speed = 1.0;
  s.max_speed = 1.5;
  s.bake_lighting();
  return s;
}

Scene corridor(std::uint64_t seed) {
  Scene s;
  s.kind = SceneKind::kCorridor;
  const double X = 20, Y = 12, Z = 2.6, w = 2.8;
  const int paint = s.add_texture(make_uniform(0.72f, 0.012f, seed + 1));
  const int paint2 = s.add_texture(make_uniform(0.6f, 0.012f, seed + 2));
  const int lower = s.add_texture(make_uniform(0.42f, 0.012f, seed + 10));
  const int floor = s.add_texture(make_tiles(256, seed + 3, 4, 0.4f, 0.015f));  // 0.6 m vinyl tiles
  const int ceiling = s.add_texture(make_tiles(256, seed + 4, 4, 0.85f, 0.01f));  // 0.6 m grid
  const int skirting = s.add_texture(make_uniform(0.22f, 0.01f, seed + 5));
  const int door_tex = s.add_texture(make_uniform(0.38f, 0.015f, seed + 6));
  const int frame = s.add_texture(make_uniform(0.9f, 0.01f, seed + 7));
  const int lamp = s.add_texture(make_uniform(0.95f, 0.0f, seed + 8));
  const int rail = s.add_texture(make_uniform(0.45f, 0.01f, seed + 9));

  const V2 o[4] = {V2(0, 0), V2(X, 0), V2(X, Y), V2(0, Y)};
  const V2 in[4] = {V2(w, w), V2(X - w, w), V2(X - w, Y - w), V2(w, Y - w)};
  s.add_quad(V3(0, 0, 0), V3(X, 0, 0), V3(0, Y, 0), floor, 2.4);
  s.add_quad(V3(0, 0, Z), V3(0, Y, 0), V3(X, 0, 0), ceiling, 2.4);
  for (int k = 0; k < 4; ++k) {
    const V2 a = o[k], b = o[(k + 1) % 4];
    const V2 ia = in[(k + 1) % 4], ib = in[k];  // inner block walls face outwards
    vquad(s, a, b, 0, Z, paint);
    vquad(s, ia, ib, 0, Z, paint2);
    // Skirting, a darker lower wall (wainscot) and a dado rail: long lines, no corners. Flat
    // bands slightly off the wall (thin box tops would alias into dashes).
    for (const auto& [p, q] : {std::pair{a, b}, std::pair{ia, ib}}) {
      vquad(s, p, q, 0, 0.1, skirting, 0, 0.004);
      vquad(s, p, q, 0.1, 0.95, lower, 0, 0.002);
      vquad(s, p, q, 0.95, 1.0, rail, 0, 0.004);
    }
    const double len = (b - a).norm();
    for (double d = 3.0; d < len - 2.0; d += 5.5) door(s, a, b, d, door_tex, frame);
    const double ilen = (ib - ia).norm();
    for (double d = 4.5; d < ilen - 2.0; d += 6.0) door(s, ia, ib, d, door_tex, frame);
    // A window near the end of each leg of the ring, where the walker turns towards it.
    {
      const V2 dir = (b - a) / len;
      for (const V2& w0 : {V2(b - dir * 1.8), V2(a + dir * 0.5)}) {
        const V2 w1 = w0 + dir * 1.1;
        vquad(s, w0, w1, 1.0, 2.1, lamp, 0, 0.006, 0.8f);
        wall_box(s, w0 - dir * 0.05, w1 + dir * 0.05, 0.94, 1.0, 0.1, frame, frame);
      }
    }
    // Shallow pilasters between the doors: long vertical edges, corners only at floor level.
    for (double d = 2.0; d < len - 2.0; d += 5.5) {
      const V2 p = a + (b - a) * (d / len);
      wall_box(s, p, p + (b - a) * (0.35 / len), 0, Z, 0.08, paint, paint);
    }
  }
  // Ceiling light panels along the centre line, and their light.
  const V2 c[4] = {V2(w / 2, w / 2), V2(X - w / 2, w / 2), V2(X - w / 2, Y - w / 2), V2(w / 2, Y - w / 2)};
  for (int k = 0; k < 4; ++k) {
    const V2 a = c[k], b = c[(k + 1) % 4];
    const double len = (b - a).norm();
    for (double d = 1.5; d < len - 1.0; d += 3.5) {
      const V2 p = a + (b - a) * (d / len);
      s.add_quad(V3(p.x() - 0.3, p.y() - 0.3, Z - 0.005), V3(0, 0.6, 0), V3(0.6, 0, 0), lamp, 0, 1.5f);
      s.lights.push_back({V3(p.x(), p.y(), Z - 0.2), 0.4, 2.5});
    }
  }
  s.ambient = 0.35;
  s.background = 0.5f;
  s.path = rounded_rect(c[0], c[2], 1.4);
  s.look_around = 0.08;  // in a corridor one looks along it, not at the walls
  s.camera_height = 1.45;
  s.nominal_speed = 1.0;
  s.max_speed = 1.5;
  s.bake_lighting();
  return s;
}

Scene street(std::uint64_t seed) {
  Scene s;
  s.kind = SceneKind::kStreet;
  Rng rng(seed ^ 0x57EE7);
  const double X = 80, Y = 50;
  const int asphalt = s.add_texture(make_noise(512, seed + 1, 0.32f, 0.12f, 16));
  const int paving = s.add_texture(make_tiles(256, seed + 2, 8, 0.55f, 0.08f));
  const int marking = s.add_texture(make_uniform(0.85f, 0.02f, seed + 3));
  const int pole = s.add_texture(make_uniform(0.3f, 0.02f, seed + 4));
  const int bricks = s.add_texture(make_bricks(512, seed + 5, 0.4f, 0.7f));
  std::vector<int> facades, cars;
  for (int k = 0; k < 5; ++k)
    facades.push_back(s.add_texture(make_facade(512, seed * 17 + 300 + k, 4, 4)));
  for (int k = 0; k < 6; ++k) cars.push_back(s.add_texture(make_car(256, seed * 17 + 400 + k)));
  const int glass = s.add_texture(make_uniform(0.12f, 0.02f, seed + 6));
  std::vector<int> signs, shop;
  for (int k = 0; k < 4; ++k) signs.push_back(s.add_texture(make_poster(256, seed * 17 + 500 + k)));
  for (int k = 0; k < 2; ++k) shop.push_back(s.add_texture(make_text_page(256, seed * 17 + 600 + k)));

  s.add_quad(V3(-40, -40, 0), V3(X + 80, 0, 0), V3(0, Y + 80, 0), asphalt, 8.0);
  // Inner and outer sidewalks (kerb height 0.15) and the building rows behind them.
  const double kerb = 5.5, front = 8.0;
  s.add_box(V3(kerb, kerb, 0), V3(X - kerb, Y - kerb, 0.15), paving, paving, 4.0);
  s.add_box(V3(-30, -30, 0), V3(X + 30, -kerb, 0.15), paving, paving, 4.0);
  s.add_box(V3(-30, Y + kerb, 0), V3(X + 30, Y + 30, 0.15), paving, paving, 4.0);
  s.add_box(V3(-30, -kerb, 0), V3(-kerb, Y + kerb, 0.15), paving, paving, 4.0);
  s.add_box(V3(X + kerb, -kerb, 0), V3(X + 30, Y + kerb, 0.15), paving, paving, 4.0);
  // A row of buildings with varying width/height/facade between two points (axis-aligned),
  // `depth` deep on the given side.
  auto row = [&](V2 a, V2 b, V2 outward) {
    const double len = (b - a).norm();
    const V2 d = (b - a) / len;
    double pos = 0;
    while (pos < len - 1) {
      const double wdt = std::min(len - pos, rng.uniform(10, 22));
      const double h = rng.uniform(9, 22);
      const V2 p0 = a + d * pos, p1 = a + d * (pos + wdt), p2 = p1 + outward * 12.0;
      const V3 lo(std::min(p0.x(), p2.x()), std::min(p0.y(), p2.y()), 0.15);
      const V3 hi(std::max(p0.x(), p2.x()), std::max(p0.y(), p2.y()), h);
      const bool brick = rng.uniform() < 0.25;
      s.add_box(lo, hi, brick ? bricks : facades[rng.integer(0, 4)], pole, brick ? 3.0 : 12.0);
      // Ground floor towards the road: a shop sign, a shop window and a door.
      // e runs along the front so that quads from -e to +e face the road (-outward).
      const V2 m = p0 + d * (wdt * 0.5), e(-outward.y(), outward.x());
      const double sw = std::min(6.0, wdt * 0.6);
      vquad(s, m - e * (sw / 2), m + e * (sw / 2), 3.0, 3.9, signs[rng.integer(0, 3)], 0, 0.03);
      vquad(s, m - e * (sw / 2), m - e * 0.5, 0.4, 2.6, shop[rng.integer(0, 1)], 0, 0.02);
      vquad(s, m + e * 0.4, m + e * 1.5, 0.15, 2.4, glass, 0, 0.02);
      pos += wdt + (rng.uniform() < 0.3 ? rng.uniform(2, 5) : 0.0);
    }
  };
  row(V2(front, front), V2(X - front, front), V2(0, 1));
  row(V2(X - front, front), V2(X - front, Y - front), V2(-1, 0));
  row(V2(X - front, Y - front), V2(front, Y - front), V2(0, -1));
  row(V2(front, Y - front), V2(front, front), V2(1, 0));
  row(V2(-front - 12, -front), V2(X + front + 12, -front), V2(0, -1));
  row(V2(X + front, -front), V2(X + front, Y + front), V2(1, 0));
  row(V2(X + front + 12, Y + front), V2(-front - 12, Y + front), V2(0, 1));
  row(V2(-front, Y + front), V2(-front, -front), V2(-1, 0));
  // Road markings: dashed centre line and continuous edge lines on each straight.
  const V2 c[4] = {V2(0, 0), V2(X, 0), V2(X, Y), V2(0, Y)};
  for (int k = 0; k < 4; ++k) {
    const V2 a = c[k], b = c[(k + 1) % 4];
    const double len = (b - a).norm();
    const V2 d = (b - a) / len, n(-d.y(), d.x());
    for (double t = 12; t < len - 12; t += 9) {
      const V2 p = a + d * t - n * 0.07;
      s.add_quad(V3(p.x(), p.y(), 0.005), V3(d.x() * 3, d.y() * 3, 0), V3(n.x() * 0.14, n.y() * 0.14, 0), marking);
    }
    for (double side : {-4.6, 4.6}) {
      const V2 p = a + d * 10 + n * side;
      // Orientation chosen so the quad faces up (u x v along +z).
      s.add_quad(V3(p.x(), p.y(), 0.005), V3(d.x() * (len - 20), d.y() * (len - 20), 0),
                 V3(n.x() * 0.12, n.y() * 0.12, 0), marking);
    }
    // Parked cars along the outer kerb, lamp posts on the sidewalk.
    for (double t = 14; t < len - 14; t += rng.uniform(7, 14)) {
      const V2 p = a + d * t - n * 4.4;
      const V2 q = p + d * 4.2;
      const V3 lo(std::min(p.x(), q.x()) - std::abs(n.x()) * 0.9, std::min(p.y(), q.y()) - std::abs(n.y()) * 0.9, 0.15);
      const V3 hi(std::max(p.x(), q.x()) + std::abs(n.x()) * 0.9, std::max(p.y(), q.y()) + std::abs(n.y()) * 0.9, 1.0);
      const int ct = cars[rng.integer(0, 5)];
      s.add_box(lo, hi, ct, ct);
      const V3 shrink(std::abs(d.x()) * 0.9 + std::abs(n.x()) * 0.1, std::abs(d.y()) * 0.9 + std::abs(n.y()) * 0.1, 0);
      s.add_box(V3(lo.x() + shrink.x(), lo.y() + shrink.y(), 1.0), V3(hi.x() - shrink.x(), hi.y() - shrink.y(), 1.5),
                glass, ct);
    }
    for (double t = 8; t < len - 4; t += 16) {
      for (double side : {-6.5, 6.5}) {
        const V2 p = a + d * t + n * side;
        s.add_box(V3(p.x() - 0.08, p.y() - 0.08, 0.15), V3(p.x() + 0.08, p.y() + 0.08, 6.0), pole, pole);
      }
    }
  }
  // Orient marking quads up: flip any whose normal points down.
  for (Quad& q : s.quads)
    if (q.u.cross(q.v).z() < 0 && q.u.z() == 0 && q.v.z() == 0 && q.origin.z() < 0.01) {
      q.origin += q.v;
      q.v = -q.v;
    }
  s.ambient = 1.0;
  s.sun_direction = V3(0.45, 0.3, 0.84).normalized();
  s.sun_power = 0.5;
  s.background = 1.05f;
  s.path = rounded_rect(V2(0, 0), V2(X, Y), 11.0);
  s.camera_height = 1.65;
  s.nominal_speed = 8.0;
  s.max_speed = 15.0;
  s.vehicle = true;
  s.bake_lighting();
  return s;
}

}  // namespace

Scene build_scene(SceneKind kind, std::uint64_t seed) {
  switch (kind) {
    case SceneKind::kOffice: return office(seed);
    case SceneKind::kCorridor: return corridor(seed);
    case SceneKind::kStreet: return street(seed);
    case SceneKind::kCalibration: return calibration_scene(calib::BoardSpec{}, seed);
  }
  return office(seed);
}

}  // namespace plslam::synth
