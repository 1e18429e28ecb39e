#include "plslam/synth/texture.h"

#include <algorithm>
#include <cmath>

namespace plslam::synth {

std::uint64_t Rng::next() {
  std::uint64_t z = (state_ += 0x9E3779B97F4A7C15ULL);
  z = (z ^ (z >> 30)) * 0xBF58476D1CE4E5B9ULL;
  z = (z ^ (z >> 27)) * 0x94D049BB133111EBULL;
  return z ^ (z >> 31);
}

void build_mips(Texture& tex) {
  tex.levels.resize(1);
  while (tex.levels.back().size > 1) {
    const TextureLevel& src = tex.levels.back();
    TextureLevel dst;
    dst.size = src.size / 2;
    dst.texels.resize(static_cast<std::size_t>(dst.size) * dst.size);
    for (int y = 0; y < dst.size; ++y)
      for (int x = 0; x < dst.size; ++x) {
        const float* r0 = &src.texels[static_cast<std::size_t>(2 * y) * src.size + 2 * x];
        const float* r1 = r0 + src.size;
        dst.texels[static_cast<std::size_t>(y) * dst.size + x] = 0.25f * (r0[0] + r0[1] + r1[0] + r1[1]);
      }
    tex.levels.push_back(std::move(dst));
  }
}

namespace {

std::uint32_t hash3(std::uint32_t x, std::uint32_t y, std::uint32_t s) {
  std::uint32_t h = x * 0x8da6b343u ^ y * 0xd8163841u ^ s * 0xcb1ab31fu;
  h ^= h >> 13;
  h *= 0x5bd1e995u;
  return h ^ (h >> 15);
}

float lattice(int x, int y, int period, std::uint32_t seed) {
  const int px = ((x % period) + period) % period, py = ((y % period) + period) % period;
  return static_cast<float>(hash3(static_cast<std::uint32_t>(px), static_cast<std::uint32_t>(py), seed) & 0xffffu) /
         65535.0f;
}

// Periodic value noise in [0, 1] with `cells` lattice cells across the unit square.
float value_noise(float u, float v, int cells, std::uint32_t seed) {
  const float x = u * cells, y = v * cells;
  const int x0 = static_cast<int>(std::floor(x)), y0 = static_cast<int>(std::floor(y));
  float fx = x - x0, fy = y - y0;
  fx = fx * fx * (3 - 2 * fx);
  fy = fy * fy * (3 - 2 * fy);
  const float a = lattice(x0, y0, cells, seed), b = lattice(x0 + 1, y0, cells, seed);
  const float c = lattice(x0, y0 + 1, cells, seed), d = lattice(x0 + 1, y0 + 1, cells, seed);
  return (a + (b - a) * fx) + ((c + (d - c) * fx) - (a + (b - a) * fx)) * fy;
}

// Fractal (fBm) noise in about [-1, 1], periodic on the unit square.
float fractal(float u, float v, int base_cells, int octaves, std::uint32_t seed) {
  float sum = 0, amp = 1, norm = 0;
  int cells = base_cells;
  for (int o = 0; o < octaves; ++o) {
    sum += amp * (2 * value_noise(u, v, cells, seed + 977u * o) - 1);
    norm += amp;
    amp *= 0.5f;
    cells *= 2;
  }
  return sum / norm;
}

Texture blank(int size, bool repeat) {
  Texture t;
  t.repeat = repeat;
  t.levels.resize(1);
  t.levels[0].size = size;
  t.levels[0].texels.assign(static_cast<std::size_t>(size) * size, 0.5f);
  return t;
}

float& at(Texture& t, int x, int y) { return t.levels[0].texels[static_cast<std::size_t>(y) * t.levels[0].size + x]; }

void finish(Texture& t) {
  for (float& v : t.levels[0].texels) v = std::clamp(v, 0.02f, 1.0f);
  build_mips(t);
}

// Fills the axis-aligned rectangle [x0,x1)x[y0,y1) (texel units, clipped) with value v.
void fill_rect(Texture& t, int x0, int y0, int x1, int y1, float v) {
  const int n = t.levels[0].size;
  for (int y = std::max(0, y0); y < std::min(n, y1); ++y)
    for (int x = std::max(0, x0); x < std::min(n, x1); ++x) at(t, x, y) = v;
}

}  // namespace

Texture make_noise(int size, std::uint64_t seed, float base, float amplitude, int base_cells) {
  Texture t = blank(size, true);
  const auto s = static_cast<std::uint32_t>(seed);
  for (int y = 0; y < size; ++y)
    for (int x = 0; x < size; ++x) {
      const float u = (x + 0.5f) / size, v = (y + 0.5f) / size;
      at(t, x, y) = base + amplitude * fractal(u, v, base_cells, 6, s);
    }
  finish(t);
  return t;
}

Texture make_uniform(float value, float noise, std::uint64_t seed) {
  return make_noise(128, seed, value, noise, 4);
}

Texture make_stripes(int size, int stripes, float a, float b) {
  Texture t = blank(size, true);
  const int period = size / stripes;
  for (int y = 0; y < size; ++y)
    for (int x = 0; x < size; ++x) at(t, x, y) = (x % period) < period * 2 / 3 ? a : b;
  finish(t);
  return t;
}

Texture make_bricks(int size, std::uint64_t seed, float brick, float mortar) {
  Texture t = blank(size, true);
  Rng rng(seed);
  const auto s = static_cast<std::uint32_t>(seed);
  const int rows = 16, cols = 8;  // bricks per texture; the quad scale makes them ~25x6.5 cm
  const int bh = size / rows, bw = size / cols, m = std::max(1, size / 128);
  std::vector<float> shade(rows * cols);
  for (float& v : shade) v = static_cast<float>(rng.uniform(-0.12, 0.12));
  for (int y = 0; y < size; ++y)
    for (int x = 0; x < size; ++x) {
      const int row = y / bh;
      const int xs = (x + (row % 2) * bw / 2) % size;
      const int col = xs / bw;
      const bool in_mortar = (y % bh) < m || (xs % bw) < m;
      const float u = (x + 0.5f) / size, v = (y + 0.5f) / size;
      const float grain = 0.06f * fractal(u, v, 32, 4, s);
      at(t, x, y) = in_mortar ? mortar + grain : brick + shade[row * cols + col] + grain;
    }
  finish(t);
  return t;
}

Texture make_tiles(int size, std::uint64_t seed, int tiles, float base, float contrast) {
  Texture t = blank(size, true);
  Rng rng(seed);
  const auto s = static_cast<std::uint32_t>(seed);
  const int tw = size / tiles, g = std::max(1, size / 256);
  std::vector<float> shade(tiles * tiles);
  for (float& v : shade) v = static_cast<float>(rng.uniform(-contrast, contrast));
  for (int y = 0; y < size; ++y)
    for (int x = 0; x < size; ++x) {
      const bool grout = (x % tw) < g || (y % tw) < g;
      const float u = (x + 0.5f) / size, v = (y + 0.5f) / size;
      const float speck = 0.05f * fractal(u, v, 16, 5, s);
      at(t, x, y) = grout ? base * 0.6f + speck : base + shade[(y / tw) * tiles + x / tw] + speck;
    }
  finish(t);
  return t;
}

Texture make_wood(int size, std::uint64_t seed, float base) {
  Texture t = blank(size, true);
  const auto s = static_cast<std::uint32_t>(seed);
  for (int y = 0; y < size; ++y)
    for (int x = 0; x < size; ++x) {
      const float u = (x + 0.5f) / size, v = (y + 0.5f) / size;
      // Rings along v, distorted by low-frequency noise; planks every 1/4 of u.
      const float warp = 0.6f * fractal(u, v, 2, 3, s);
      const float rings = std::sin(6.2831853f * (8 * v + 3 * warp + 0.25f * std::floor(4 * u)));
      const bool gap = std::fmod(u * 4, 1.0f) < 0.012f;
      at(t, x, y) = gap ? base * 0.35f : base + 0.08f * rings + 0.05f * fractal(u, v, 64, 3, s + 5);
    }
  finish(t);
  return t;
}

Texture make_text_page(int size, std::uint64_t seed) {
  Texture t = blank(size, false);
  Rng rng(seed);
  fill_rect(t, 0, 0, size, size, 0.88f);
  const int margin = size / 10, line = size / 28;
  int y = margin;
  // A title line of big blocks, then paragraphs of word-like dark blocks.
  for (int x = margin; x < size - margin * 3;) {
    const int w = rng.integer(size / 20, size / 8);
    fill_rect(t, x, y, x + w, y + line * 2 - line / 3, 0.12f);
    x += w + size / 40;
  }
  y += line * 3;
  while (y < size - margin - line) {
    int x = margin;
    const int end = rng.uniform() < 0.15 ? size / 2 : size - margin;
    while (x < end) {
      const int w = rng.integer(size / 60, size / 14);
      fill_rect(t, x, y, std::min(x + w, end), y + line / 2 + 1, 0.18f + static_cast<float>(rng.uniform(0, 0.1)));
      x += w + size / 70 + 1;
    }
    y += rng.uniform() < 0.12 ? line * 2 : line;
  }
  finish(t);
  return t;
}

Texture make_poster(int size, std::uint64_t seed) {
  Texture t = blank(size, false);
  Rng rng(seed);
  const auto s = static_cast<std::uint32_t>(seed);
  const float bg = static_cast<float>(rng.uniform(0.25, 0.8));
  for (int y = 0; y < size; ++y)
    for (int x = 0; x < size; ++x)
      at(t, x, y) = bg + 0.05f * fractal((x + 0.5f) / size, (y + 0.5f) / size, 4, 3, s);
  const int shapes = rng.integer(7, 14);
  for (int k = 0; k < shapes; ++k) {
    const float v = static_cast<float>(rng.uniform(0.05, 0.95));
    const int cx = rng.integer(0, size), cy = rng.integer(0, size);
    const int r = rng.integer(size / 14, size / 4);
    const int kind = rng.integer(0, 2);
    for (int y = std::max(0, cy - r); y < std::min(size, cy + r); ++y)
      for (int x = std::max(0, cx - r); x < std::min(size, cx + r); ++x) {
        const int dx = x - cx, dy = y - cy;
        bool inside = false;
        if (kind == 0) inside = dx * dx + dy * dy < r * r;                        // disc
        else if (kind == 1) inside = std::abs(dx) < r && std::abs(dy) < r * 2 / 3;  // rectangle
        else inside = dy > -r && 2 * std::abs(dx) < dy + r;                       // triangle
        if (inside) at(t, x, y) = v;
      }
  }
  // A white border like a printed sheet.
  const int b = size / 24;
  fill_rect(t, 0, 0, size, b, 0.9f);
  fill_rect(t, 0, size - b, size, size, 0.9f);
  fill_rect(t, 0, 0, b, size, 0.9f);
  fill_rect(t, size - b, 0, size, size, 0.9f);
  finish(t);
  return t;
}

Texture make_books(int size, std::uint64_t seed) {
  Texture t = blank(size, true);
  Rng rng(seed);
  const auto s = static_cast<std::uint32_t>(seed);
  // 4 shelves per texture height; each shelf a row of spines of random width, height and tone.
  const int shelf = size / 4;
  for (int row = 0; row < 4; ++row) {
    const int y0 = row * shelf;
    fill_rect(t, 0, y0, size, y0 + shelf, 0.08f);  // dark back of the shelf
    int x = 0;
    while (x < size) {
      const int w = rng.integer(size / 64, size / 20);
      const int h = rng.integer(shelf * 6 / 10, shelf * 9 / 10);
      const float v = static_cast<float>(rng.uniform(0.15, 0.85));
      fill_rect(t, x, y0 + shelf - h, std::min(size, x + w - 1), y0 + shelf, v);
      // A label band on some spines.
      if (rng.uniform() < 0.5) {
        const int ly = y0 + shelf - h + h / 5;
        fill_rect(t, x + 1, ly, std::min(size, x + w - 2), ly + h / 8, v > 0.5f ? v - 0.4f : v + 0.4f);
      }
      x += w;
    }
    fill_rect(t, 0, y0 + shelf - shelf / 16, size, y0 + shelf, 0.55f);  // the shelf board
  }
  for (int y = 0; y < size; ++y)
    for (int x = 0; x < size; ++x) at(t, x, y) += 0.03f * fractal((x + 0.5f) / size, (y + 0.5f) / size, 32, 3, s);
  finish(t);
  return t;
}

Texture make_facade(int size, std::uint64_t seed, int cols, int rows) {
  Texture t = blank(size, true);
  Rng rng(seed);
  const auto s = static_cast<std::uint32_t>(seed);
  const float wall = static_cast<float>(rng.uniform(0.45, 0.75));
  for (int y = 0; y < size; ++y)
    for (int x = 0; x < size; ++x)
      at(t, x, y) = wall + 0.06f * fractal((x + 0.5f) / size, (y + 0.5f) / size, 8, 5, s);
  const int cw = size / cols, rh = size / rows;
  for (int r = 0; r < rows; ++r)
    for (int c = 0; c < cols; ++c) {
      const int x0 = c * cw + cw / 4, x1 = c * cw + cw * 3 / 4;
      const int y0 = r * rh + rh / 4, y1 = r * rh + rh * 3 / 4;
      fill_rect(t, x0 - 2, y0 - 2, x1 + 2, y1 + 2, wall * 0.55f);  // frame
      const float glass = static_cast<float>(rng.uniform(0.08, 0.35));
      fill_rect(t, x0, y0, x1, y1, glass);
      fill_rect(t, (x0 + x1) / 2 - 1, y0, (x0 + x1) / 2 + 1, y1, wall * 0.55f);  // mullion
      if (rng.uniform() < 0.4) fill_rect(t, x0, y0, x1, (y0 + y1) / 2, glass + 0.3f);  // blind
      fill_rect(t, x0 - 4, y1 + 2, x1 + 4, y1 + 5, std::min(1.0f, wall + 0.2f));        // sill
    }
  finish(t);
  return t;
}

Texture make_car(int size, std::uint64_t seed) {
  Texture t = blank(size, false);
  Rng rng(seed);
  const auto s = static_cast<std::uint32_t>(seed);
  const float paint = static_cast<float>(rng.uniform(0.15, 0.85));
  for (int y = 0; y < size; ++y)
    for (int x = 0; x < size; ++x)
      at(t, x, y) = paint + 0.03f * fractal((x + 0.5f) / size, (y + 0.5f) / size, 8, 3, s);
  // Windows in the upper part (texture v grows downward = world down), wheels at the bottom.
  fill_rect(t, size / 5, size / 10, size / 2 - 4, size * 4 / 10, 0.1f);
  fill_rect(t, size / 2 + 4, size / 10, size * 4 / 5, size * 4 / 10, 0.1f);
  for (int w = 0; w < 2; ++w) {
    const int cx = w == 0 ? size / 5 : size * 4 / 5, cy = size * 9 / 10, r = size / 9;
    for (int y = cy - r; y < std::min(size, cy + r); ++y)
      for (int x = cx - r; x < cx + r; ++x)
        if ((x - cx) * (x - cx) + (y - cy) * (y - cy) < r * r) at(t, x, y) = 0.05f;
  }
  fill_rect(t, size / 2 - 2, size / 2, size / 2 + 2, size * 8 / 10, paint * 0.6f);  // door gap
  finish(t);
  return t;
}

}  // namespace plslam::synth
