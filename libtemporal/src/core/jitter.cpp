#include "temporal/core/jitter.h"

#include <glm/gtc/matrix_transform.hpp>

namespace temporal {

Expected<JitterMode> parse_jitter_mode(const std::string& name) {
  if (name == "regular") return JitterMode::Regular;
  if (name == "regular-raster") return JitterMode::RegularRaster;
  if (name == "halton") return JitterMode::Halton;
  if (name == "random") return JitterMode::Random;
  if (name == "none") return JitterMode::None;
  return Error::usage("unknown jitter '" + name + "': use regular, regular-raster, halton, random or none");
}

const char* to_string(JitterMode mode) {
  switch (mode) {
    case JitterMode::Regular: return "regular";
    case JitterMode::RegularRaster: return "regular-raster";
    case JitterMode::Halton: return "halton";
    case JitterMode::Random: return "random";
    case JitterMode::None: return "none";
  }
  return "none";
}

int regular_jitter_index(int frame, int k) {
  const int n = k * k;
  return ((frame % n) + n) % n;
}

namespace {
// The value of the 2^m x 2^m Bayer (ordered-dither) matrix at (x, y): M(2n) = [[4M, 4M + 2], [4M + 3, 4M + 1]], the
// least significant bit of the coordinates giving the most significant digit, so consecutive values are as far
// apart as the grid allows (2x2: 0 top-left, 1 bottom-right, 2 top-right, 3 bottom-left).
int bayer_value(int x, int y, int m) {
  int v = 0;
  for (int bit = 0; bit < m; ++bit) {
    const int xb = (x >> bit) & 1, yb = (y >> bit) & 1;
    v = (v << 2) | (((xb ^ yb) << 1) | yb);
  }
  return v;
}
}  // namespace

glm::ivec2 regular_subpixel(int k, int index, bool raster) {
  if (k <= 1) return {0, 0};
  const int n = k * k;
  index = ((index % n) + n) % n;
  if (raster) return {index % k, index / k};
  // Dispersed order: the cells ranked by the Bayer value of the power-of-two grid P >= k they fall in
  // (floor(s P / k) is one-to-one for P >= k, so the ranks are a permutation; for k = 2^m it is Bayer's order).
  int m = 0;
  while ((1 << m) < k) ++m;
  const int p = 1 << m;
  auto key = [&](int cell) { return bayer_value((cell % k) * p / k, (cell / k) * p / k, m); };
  for (int c = 0; c < n; ++c) {  // the cell with exactly `index` smaller keys (n <= 1024: a frame's set-up)
    int rank = 0;
    const int kc = key(c);
    for (int d = 0; d < n; ++d) rank += key(d) < kc;
    if (rank == index) return {c % k, c / k};
  }
  return {0, 0};  // unreachable: the keys are distinct
}

glm::vec2 regular_jitter(int k, int index, bool raster) {
  const glm::ivec2 s = regular_subpixel(k, index, raster);
  return {(float(s.x) + 0.5f) / float(k) - 0.5f, (float(s.y) + 0.5f) / float(k) - 0.5f};
}

float radical_inverse(std::uint32_t index, std::uint32_t base) {
  // Accumulated in double: the result is exact for the first 2^24 indices of base 2.
  double inv = 1.0 / base, f = inv, r = 0.0;
  while (index > 0) {
    r += f * double(index % base);
    index /= base;
    f *= inv;
  }
  return float(r);
}

std::uint32_t hash_u32(std::uint32_t a, std::uint32_t b, std::uint32_t c, std::uint32_t d) {
  // A chain of the lowbias32 finaliser (Wellons): good avalanche, four multiplies per word.
  auto mix = [](std::uint32_t x) {
    x ^= x >> 16;
    x *= 0x7feb352dU;
    x ^= x >> 15;
    x *= 0x846ca68bU;
    x ^= x >> 16;
    return x;
  };
  std::uint32_t h = mix(a + 0x9e3779b9U);
  h = mix(h ^ (b + 0x85ebca6bU));
  h = mix(h ^ (c + 0xc2b2ae35U));
  h = mix(h ^ (d + 0x27d4eb2fU));
  return h;
}

glm::vec2 frame_jitter(JitterMode mode, int frame, int k, std::uint32_t seed) {
  switch (mode) {
    case JitterMode::Regular: return regular_jitter(k, regular_jitter_index(frame, k));
    case JitterMode::RegularRaster: return regular_jitter(k, regular_jitter_index(frame, k), true);
    case JitterMode::Halton: {
      const auto i = std::uint32_t(((frame % 1024) + 1024) % 1024) + 1;  // index 0 would be (0, 0) = corner
      return {radical_inverse(i, 2) - 0.5f, radical_inverse(i, 3) - 0.5f};
    }
    case JitterMode::Random: {
      // 24 random bits per axis -> exactly representable floats in [0, 1).
      const float u = float(hash_u32(seed, std::uint32_t(frame), 1) >> 8) * (1.0f / 16777216.0f);
      const float v = float(hash_u32(seed, std::uint32_t(frame), 2) >> 8) * (1.0f / 16777216.0f);
      return {u - 0.5f, v - 0.5f};
    }
    case JitterMode::None: return {0.0f, 0.0f};
  }
  return {0.0f, 0.0f};
}

glm::mat4 jitter_projection(const glm::mat4& projection, glm::vec2 jitter, int width, int height) {
  // The sample for pixel x is taken at x + 0.5 + jx: the scene moves by -jx pixels under a fixed pixel grid.
  const glm::vec3 t(-2.0f * jitter.x / float(width), 2.0f * jitter.y / float(height), 0.0f);
  return glm::translate(glm::mat4(1.0f), t) * projection;
}

}  // namespace temporal
