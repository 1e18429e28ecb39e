#include "plslam/synth/renderer.h"

#include <algorithm>
#include <cmath>
#include <cstring>
#include <type_traits>

namespace plslam::synth {

namespace {

constexpr double kNear = 0.05;  // metres; geometry closer than this is clipped
constexpr float kEdgeEps = 1e-5f;

// Rotated-grid 4x supersampling pattern (offsets from the pixel centre).
constexpr float kSub[4][2] = {{-0.125f, -0.375f}, {0.375f, -0.125f}, {0.125f, 0.375f}, {-0.375f, 0.125f}};

template <bool kRepeat>
inline float bilinear_t(const TextureLevel& lv, float u, float v) {
  constexpr bool repeat = kRepeat;
  const int n = lv.size;
  const float uu = u - 0.5f, vv = v - 0.5f;
  // floor() without a libm call: truncate, then step down for negatives.
  int iu = static_cast<int>(uu), iv = static_cast<int>(vv);
  iu -= uu < static_cast<float>(iu);
  iv -= vv < static_cast<float>(iv);
  const float fu = static_cast<float>(iu), fv = static_cast<float>(iv);
  const float au = uu - fu, av = vv - fv;
  int x0, x1, y0, y1;
  if constexpr (repeat) {
    const int m = n - 1;
    x0 = iu & m;
    y0 = iv & m;
    x1 = (x0 + 1) & m;
    y1 = (y0 + 1) & m;
  } else {
    x0 = std::clamp(iu, 0, n - 1);
    y0 = std::clamp(iv, 0, n - 1);
    x1 = std::clamp(iu + 1, 0, n - 1);
    y1 = std::clamp(iv + 1, 0, n - 1);
  }
  const float* r0 = &lv.texels[static_cast<std::size_t>(y0) * n];
  const float* r1 = &lv.texels[static_cast<std::size_t>(y1) * n];
  const float top = r0[x0] + (r0[x1] - r0[x0]) * au;
  const float bot = r1[x0] + (r1[x1] - r1[x0]) * au;
  return top + (bot - top) * av;
}

inline float bilinear(const TextureLevel& lv, bool repeat, float u, float v) {
  return repeat ? bilinear_t<true>(lv, u, v) : bilinear_t<false>(lv, u, v);
}

}  // namespace

Renderer::Renderer(const Scene& scene, const PinholeCamera& camera) : scene_(scene), cam_(camera) {
  views_.resize(scene.quads.size());
  visible_.resize(scene.quads.size());
  const std::size_t n = static_cast<std::size_t>(cam_.width) * cam_.height;
  inv_depth_.resize(n);
  id_.resize(n);
  edge_.resize(n);
}

bool Renderer::setup_quad(int qi, const Eigen::Matrix3d& R_cw, const Eigen::Vector3d& t_cw, QuadView& qv) const {
  const Quad& q = scene_.quads[qi];
  const Eigen::Vector3d O = R_cw * q.origin + t_cw, U = R_cw * q.u, V = R_cw * q.v;
  const Eigen::Vector3d N = U.cross(V);
  const double on = O.dot(N);
  if (on >= -1e-12) return false;  // the camera sees the back side (or the plane edge-on)
  const Eigen::Vector3d Vn = V.cross(N), Un = N.cross(U);
  const Eigen::Vector3d fa = on * Vn - O.dot(Vn) * N;
  const Eigen::Vector3d fb = on * Un - O.dot(Un) * N;
  const Eigen::Vector3d fw = N.squaredNorm() * N;
  // d = K^-1 (x, y, 1): turn coefficients on d into coefficients on the pixel position.
  auto to_pixel = [&](const Eigen::Vector3d& f) {
    return Eigen::Vector3d(f.x() / cam_.fx, f.y() / cam_.fy,
                           f.z() - f.x() * cam_.cx / cam_.fx - f.y() * cam_.cy / cam_.fy);
  };
  const Eigen::Vector3d ga = to_pixel(fa), gb = to_pixel(fb), gw = to_pixel(fw);
  const double k = 1.0 / gw.norm();  // normalise so values stay near 1 in float
  qv.a = (ga * k).cast<float>();
  qv.b = (gb * k).cast<float>();
  qv.w = (gw * k).cast<float>();
  qv.inv_depth_scale = static_cast<float>(1.0 / (N.squaredNorm() * on * k));
  return true;
}

void Renderer::rasterize(int qi, const Eigen::Matrix3d& R_cw, const Eigen::Vector3d& t_cw) {
  const Quad& q = scene_.quads[qi];
  const QuadView& v = views_[qi];
  // Near-plane clipping of the outline (Sutherland-Hodgman, one plane).
  const Eigen::Vector3d c[4] = {q.origin, q.origin + q.u, q.origin + q.u + q.v, q.origin + q.v};
  Eigen::Vector3d in[4];
  for (int k = 0; k < 4; ++k) in[k] = R_cw * c[k] + t_cw;
  Eigen::Vector2d poly[8];
  int np = 0;
  for (int k = 0; k < 4; ++k) {
    const Eigen::Vector3d& p = in[k];
    const Eigen::Vector3d& n = in[(k + 1) % 4];
    const bool pin = p.z() >= kNear, nin = n.z() >= kNear;
    auto proj = [&](const Eigen::Vector3d& X) {
      return Eigen::Vector2d(cam_.fx * X.x() / X.z() + cam_.cx, cam_.fy * X.y() / X.z() + cam_.cy);
    };
    if (pin) poly[np++] = proj(p);
    if (pin != nin) {
      const double a = (kNear - p.z()) / (n.z() - p.z());
      poly[np++] = proj(p + a * (n - p));
    }
  }
  if (np < 3) return;
  double ymin = 1e30, ymax = -1e30;
  for (int k = 0; k < np; ++k) {
    ymin = std::min(ymin, poly[k].y());
    ymax = std::max(ymax, poly[k].y());
  }
  const int W = cam_.width, H = cam_.height;
  const int y0 = std::max(0, static_cast<int>(std::floor(ymin)) - 1);
  const int y1 = std::min(H - 1, static_cast<int>(std::ceil(ymax)) + 1);
  for (int y = y0; y <= y1; ++y) {
    // Span of the convex outline on this row, padded by a pixel; the exact test is per pixel.
    double xmin = 1e30, xmax = -1e30;
    const double yc = y;
    for (int k = 0; k < np; ++k) {
      const Eigen::Vector2d& p = poly[k];
      const Eigen::Vector2d& n = poly[(k + 1) % np];
      const double lo = std::min(p.y(), n.y()) - 1, hi = std::max(p.y(), n.y()) + 1;
      if (yc < lo || yc > hi) continue;
      double x;
      if (std::abs(n.y() - p.y()) < 1e-9) {
        xmin = std::min({xmin, p.x(), n.x()});
        xmax = std::max({xmax, p.x(), n.x()});
        continue;
      }
      const double a = std::clamp((yc - p.y()) / (n.y() - p.y()), 0.0, 1.0);
      x = p.x() + a * (n.x() - p.x());
      xmin = std::min(xmin, x);
      xmax = std::max(xmax, x);
    }
    if (xmin > xmax) continue;
    const int x0 = std::max(0, static_cast<int>(std::floor(xmin)) - 1);
    const int x1 = std::min(W - 1, static_cast<int>(std::ceil(xmax)) + 1);
    const float fy = static_cast<float>(y);
    const float ar = v.a.y() * fy + v.a.z(), br = v.b.y() * fy + v.b.z(), wr = v.w.y() * fy + v.w.z();
    float* zb = &inv_depth_[static_cast<std::size_t>(y) * W];
    std::int32_t* ib = &id_[static_cast<std::size_t>(y) * W];
    constexpr float kMaxInvDepth = static_cast<float>(1.0 / kNear);
    for (int x = x0; x <= x1; ++x) {
      const float fx = static_cast<float>(x);
      const float w = v.w.x() * fx + wr;
      const float iz = w * v.inv_depth_scale;
      if (!(iz > zb[x]) || iz > kMaxInvDepth) continue;
      const float iw = 1.0f / w;
      const float s = (v.a.x() * fx + ar) * iw, t = (v.b.x() * fx + br) * iw;
      if (s < -kEdgeEps || s > 1 + kEdgeEps || t < -kEdgeEps || t > 1 + kEdgeEps) continue;
      zb[x] = iz;
      ib[x] = qi;
    }
  }
}

float Renderer::coverage(int qi, float x, float y) const {
  const QuadView& v = views_[qi];
  const float w = v.w.x() * x + v.w.y() * y + v.w.z();
  const float iz = w * v.inv_depth_scale;
  if (!(iz > 0) || iz > static_cast<float>(1.0 / kNear)) return 0;
  const float s = (v.a.x() * x + v.a.y() * y + v.a.z()) / w;
  const float t = (v.b.x() * x + v.b.y() * y + v.b.z()) / w;
  if (s < 0 || s > 1 || t < 0 || t > 1) return 0;
  return iz;
}

Renderer::PointShading Renderer::point_shading(int qi, float x, float y) const {
  const QuadView& v = views_[qi];
  const Quad& q = scene_.quads[qi];
  const Texture& tex = scene_.textures[q.texture];
  const float w = v.w.x() * x + v.w.y() * y + v.w.z();
  const float iw = 1.0f / w;
  const float s = std::clamp((v.a.x() * x + v.a.y() * y + v.a.z()) * iw, 0.0f, 1.0f);
  const float t = std::clamp((v.b.x() * x + v.b.y() * y + v.b.z()) * iw, 0.0f, 1.0f);
  const float n0 = static_cast<float>(tex.size());
  const float su = q.repeat_u * n0, sv = q.repeat_v * n0;
  // Texel footprint of one pixel from the homography's derivatives -> mip level
  // floor(log2(footprint)) = floor(exponent(f2) / 2), read from the float's bits.
  const float dudx = (v.a.x() - s * v.w.x()) * iw * su, dvdx = (v.b.x() - t * v.w.x()) * iw * sv;
  const float dudy = (v.a.y() - s * v.w.y()) * iw * su, dvdy = (v.b.y() - t * v.w.y()) * iw * sv;
  const float f2 = std::max(dudx * dudx + dvdx * dvdx, dudy * dudy + dvdy * dvdy);
  const int top = static_cast<int>(tex.levels.size()) - 1;
  PointShading out;
  out.level = 0;
  if (f2 > 1.0f) {
    std::uint32_t bits;
    std::memcpy(&bits, &f2, sizeof bits);
    out.level = std::min(static_cast<int>((bits >> 23) & 0xffu) - 127, 2 * top) / 2;
  }
  // Baked illumination, bilinear over the quad's grid.
  const float gx = s * static_cast<float>(q.grid_u - 1), gy = t * static_cast<float>(q.grid_v - 1);
  const int ix = std::min(static_cast<int>(gx), q.grid_u - 2), iy = std::min(static_cast<int>(gy), q.grid_v - 2);
  const float ax = gx - static_cast<float>(ix), ay = gy - static_cast<float>(iy);
  const float* L0 = &q.light[static_cast<std::size_t>(iy) * q.grid_u + ix];
  const float* L1 = L0 + q.grid_u;
  const float l0 = L0[0] + (L0[1] - L0[0]) * ax, l1 = L1[0] + (L1[1] - L1[0]) * ax;
  out.light = l0 + (l1 - l0) * ay;
  out.s = s;
  out.t = t;
  return out;
}

float Renderer::shade(int qi, float x, float y) const {
  const Quad& q = scene_.quads[qi];
  const Texture& tex = scene_.textures[q.texture];
  const PointShading p = point_shading(qi, x, y);
  const float scale = static_cast<float>(tex.size()) / static_cast<float>(1 << p.level);
  return p.light * bilinear(tex.levels[p.level], tex.repeat, p.s * q.repeat_u * scale, p.t * q.repeat_v * scale);
}

void Renderer::shade_run(int qi, int y, int x0, int x1, float* out) const {
  // Mip level and illumination vary slowly: evaluate them at the ends of blocks of 8 pixels
  // and interpolate; the texture coordinates themselves are exact per pixel.
  constexpr int kBlock = 8;
  const QuadView& v = views_[qi];
  const Quad& q = scene_.quads[qi];
  const Texture& tex = scene_.textures[q.texture];
  const float fy = static_cast<float>(y);
  const float ar = v.a.y() * fy + v.a.z(), br = v.b.y() * fy + v.b.z(), wr = v.w.y() * fy + v.w.z();
  const float n0 = static_cast<float>(tex.size());
  PointShading next = point_shading(qi, static_cast<float>(x0), fy);
  for (int xb = x0; xb < x1; xb += kBlock) {
    const int xe = std::min(xb + kBlock, x1);
    const PointShading first = next;
    next = point_shading(qi, static_cast<float>(xe), fy);
    const TextureLevel& lv = tex.levels[first.level];
    const float scale = n0 / static_cast<float>(1 << first.level);
    const float su = q.repeat_u * scale, sv = q.repeat_v * scale;
    const float dl = (next.light - first.light) / static_cast<float>(xe - xb);
    auto span = [&](auto repeat_tag) {
      constexpr bool kRepeat = decltype(repeat_tag)::value;
      float light = first.light;
      for (int x = xb; x < xe; ++x, light += dl) {
        const float fx = static_cast<float>(x);
        const float iw = 1.0f / (v.w.x() * fx + wr);
        const float s = std::clamp((v.a.x() * fx + ar) * iw, 0.0f, 1.0f);
        const float t = std::clamp((v.b.x() * fx + br) * iw, 0.0f, 1.0f);
        out[x] = light * bilinear_t<kRepeat>(lv, s * su, t * sv);
      }
    };
    if (tex.repeat) span(std::true_type{});
    else span(std::false_type{});
  }
}

void Renderer::render(const Eigen::Isometry3d& T_wc, cv::Mat& radiance, cv::Mat* depth) {
  const Eigen::Isometry3d T_cw = T_wc.inverse();
  const Eigen::Matrix3d R_cw = T_cw.rotation();
  const Eigen::Vector3d t_cw = T_cw.translation();
  const int W = cam_.width, H = cam_.height;
  std::fill(inv_depth_.begin(), inv_depth_.end(), 0.0f);
  std::fill(id_.begin(), id_.end(), -1);
  // Front to back (by the distance to each quad's closest point), so that the depth test
  // rejects most hidden pixels before any division.
  order_.clear();
  const Eigen::Vector3d cam_w = T_wc.translation();
  for (std::size_t qi = 0; qi < scene_.quads.size(); ++qi) {
    visible_[qi] = setup_quad(static_cast<int>(qi), R_cw, t_cw, views_[qi]);
    if (!visible_[qi]) continue;
    const Quad& q = scene_.quads[qi];
    const Eigen::Vector3d d = cam_w - q.origin;
    const double s = std::clamp(d.dot(q.u) / q.u.squaredNorm(), 0.0, 1.0);
    const double t = std::clamp(d.dot(q.v) / q.v.squaredNorm(), 0.0, 1.0);
    order_.push_back({(q.origin + s * q.u + t * q.v - cam_w).squaredNorm(), static_cast<int>(qi)});
  }
  std::sort(order_.begin(), order_.end());
  for (const auto& [dist, qi] : order_) rasterize(qi, R_cw, t_cw);

  radiance.create(H, W, CV_32F);
  for (int y = 0; y < H; ++y) {
    float* out = radiance.ptr<float>(y);
    const std::int32_t* ib = &id_[static_cast<std::size_t>(y) * W];
    for (int x = 0; x < W;) {
      int end = x + 1;
      while (end < W && ib[end] == ib[x]) ++end;
      if (ib[x] < 0) std::fill(out + x, out + end, scene_.background);
      else shade_run(ib[x], y, x, end, out);
      x = end;
    }
  }

  // Anti-aliasing: re-shade pixels whose 4-neighbourhood sees another surface.
  // Branch-free marking first (both sides of every horizontal and vertical change).
  std::fill(edge_.begin(), edge_.end(), std::uint8_t{0});
  for (int y = 0; y < H; ++y) {
    const std::int32_t* ib = &id_[static_cast<std::size_t>(y) * W];
    std::uint8_t* e = &edge_[static_cast<std::size_t>(y) * W];
    for (int x = 0; x + 1 < W; ++x) {
      const std::uint8_t d = ib[x] != ib[x + 1];
      e[x] |= d;
      e[x + 1] |= d;
    }
    if (y + 1 < H)
      for (int x = 0; x < W; ++x) {
        const std::uint8_t d = ib[x] != ib[x + W];
        e[x] |= d;
        e[x + W] |= d;
      }
  }
  for (int y = 0; y < H; ++y) {
    float* out = radiance.ptr<float>(y);
    const std::uint8_t* e = &edge_[static_cast<std::size_t>(y) * W];
    for (int x = 0; x < W; ++x) {
      if (!e[x]) continue;
      std::int32_t cand[9];
      int nc = 0;
      for (int dy = -1; dy <= 1; ++dy)
        for (int dx = -1; dx <= 1; ++dx) {
          const int xx = x + dx, yy = y + dy;
          if (xx < 0 || yy < 0 || xx >= W || yy >= H) continue;
          const std::int32_t id = id_[static_cast<std::size_t>(yy) * W + xx];
          if (id >= 0 && std::find(cand, cand + nc, id) == cand + nc) cand[nc++] = id;
        }
      // Coverage of each candidate by the 4 sub-samples; each covering surface is shaded once,
      // at its first covered sub-sample, and weighted by its coverage.
      int count[10] = {0};
      float at_x[10], at_y[10];
      for (const auto& o : kSub) {
        const float sx = static_cast<float>(x) + o[0], sy = static_cast<float>(y) + o[1];
        int best = nc;  // nc stands for the background
        float best_iz = 0;
        for (int k = 0; k < nc; ++k) {
          const float iz = coverage(cand[k], sx, sy);
          if (iz > best_iz) {
            best_iz = iz;
            best = k;
          }
        }
        if (count[best]++ == 0) {
          at_x[best] = sx;
          at_y[best] = sy;
        }
      }
      float sum = static_cast<float>(count[nc]) * scene_.background;
      for (int k = 0; k < nc; ++k)
        if (count[k] > 0) sum += static_cast<float>(count[k]) * shade(cand[k], at_x[k], at_y[k]);
      out[x] = 0.25f * sum;
    }
  }

  if (depth) {
    depth->create(H, W, CV_32F);
    for (int y = 0; y < H; ++y) {
      float* d = depth->ptr<float>(y);
      const float* zb = &inv_depth_[static_cast<std::size_t>(y) * W];
      for (int x = 0; x < W; ++x) d[x] = zb[x] > 0 ? 1.0f / zb[x] : 0.0f;
    }
  }
}

}  // namespace plslam::synth
