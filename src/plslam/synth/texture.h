#pragma once
// Procedural textures, generated once at scene build time into float reflectance images with a
// mip pyramid, so rendering is a cheap filtered lookup. Everything derives from a seed so the
// same seed gives the same bytes.
#include <cstdint>
#include <vector>

namespace plslam::synth {

// One mip level: size x size floats, reflectance in [0, 1].
struct TextureLevel {
  int size = 0;
  std::vector<float> texels;
};

struct Texture {
  std::vector<TextureLevel> levels;  // levels[0] is full resolution; each next halves the size
  bool repeat = true;                // tile (bricks, noise) or clamp (posters, doors)
  int size() const { return levels.front().size; }
};

// Fills the mip pyramid of a texture whose level 0 is set (size must be a power of two).
void build_mips(Texture& tex);

// Small deterministic generator (splitmix64) used everywhere instead of <random>, whose
// distributions are not specified bit-exactly across standard libraries.
class Rng {
 public:
  explicit Rng(std::uint64_t seed) : state_(seed) {}
  std::uint64_t next();
  double uniform() { return static_cast<double>(next() >> 11) * (1.0 / 9007199254740992.0); }
  double uniform(double lo, double hi) { return lo + (hi - lo) * uniform(); }
  int integer(int lo, int hi) { return lo + static_cast<int>(next() % static_cast<std::uint64_t>(hi - lo + 1)); }

 private:
  std::uint64_t state_;
};

// Generators. `size` is a power of two; `seed` selects the variant.
Texture make_noise(int size, std::uint64_t seed, float base, float amplitude, int base_cells);
Texture make_bricks(int size, std::uint64_t seed, float brick, float mortar);
Texture make_tiles(int size, std::uint64_t seed, int tiles, float base, float contrast);
Texture make_wood(int size, std::uint64_t seed, float base);
Texture make_text_page(int size, std::uint64_t seed);      // printed-text-like blocks on paper
Texture make_poster(int size, std::uint64_t seed);         // geometric shapes on a background
Texture make_books(int size, std::uint64_t seed);          // shelf of book spines
Texture make_facade(int size, std::uint64_t seed, int cols, int rows);  // windows on plaster
Texture make_car(int size, std::uint64_t seed);            // car-side-like paint with windows
Texture make_stripes(int size, int stripes, float a, float b);  // vertical ribs (radiators)
Texture make_uniform(float value, float noise, std::uint64_t seed);     // painted, low texture

}  // namespace plslam::synth
