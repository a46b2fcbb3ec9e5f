// Sub-pixel jitter: which position inside each pixel a frame samples (docs/conventions.md, "Jitter").
//
// A jitter (jx, jy) is in pixels of the image that carries it, in [-0.5, 0.5), y down: pixel (x, y) is
// sampled at image position (x + 0.5 + jx, y + 0.5 + jy). It is applied as a translation of the projection
// matrix (jitter_projection), so rasterisation, interpolation and depth all follow it exactly.
#pragma once

#include "temporal/core/error.h"

#include <glm/mat4x4.hpp>
#include <glm/vec2.hpp>
#include <glm/ext/vector_int2.hpp>

#include <cstdint>
#include <string>

namespace temporal {

enum class JitterMode {
  Regular,        // the k x k grid of seed 000, Figure 2: index i = frame mod k*k, dispersed (Bayer) order
  RegularRaster,  // the same grid in raster order (the order before issue 15; for before/after measurements)
  Halton,   // Halton (2, 3), index frame + 1, period 1024 frames
  Random,   // uniform in [-0.5, 0.5)^2 from a hash of (seed, frame): white-noise jitter (seed 003's input)
  None,     // pixel centres
};

// Parses "regular|halton|random|none"; the error lists the accepted names.
Expected<JitterMode> parse_jitter_mode(const std::string& name);
const char* to_string(JitterMode mode);

// The regular pattern of docs/conventions.md: index i in 0..k*k-1 is sub-pixel (sx, sy) in 0..k-1, in the
// dispersed order (the i-th cell of the k x k grid ranked by the Bayer matrix of the next power of two; for
// k = 4: (0,0) (2,2) (2,0) (0,2) (1,1) (3,3) (3,1) (1,3) (1,0) (3,2) ...), or in raster order (i mod k, i div k)
// with `raster`. Seed 000 Figure 2 leaves the order open; the dispersed one spreads every run of consecutive
// frames over the pixel, so a history that holds only a few frames still sees samples all around each pixel.
// An index outside 0..k*k-1 is taken mod k*k. k = 1 gives (0, 0).
glm::ivec2 regular_subpixel(int k, int index, bool raster = false);
// The jitter of that sub-pixel: ((sx + 0.5) / k - 0.5, (sy + 0.5) / k - 0.5).
glm::vec2 regular_jitter(int k, int index, bool raster = false);

// The radical inverse of `index` in `base` (index >= 0), in [0, 1).
float radical_inverse(std::uint32_t index, std::uint32_t base);

// The jitter of `frame` for a mode. `k` is the regular grid size (ignored by the other modes); `seed`
// decorrelates random jitter between runs (the same seed and frame always give the same value).
glm::vec2 frame_jitter(JitterMode mode, int frame, int k, std::uint32_t seed);

// Index in the regular k x k pattern used by frame N: N mod k*k (non-negative for negative frames too).
int regular_jitter_index(int frame, int k);

// `projection` translated so that the image is sampled at the jittered positions, for an image of
// width x height pixels: clip-space x shifts by -2 jx / width, y by +2 jy / height (image y is down,
// NDC y is up).
glm::mat4 jitter_projection(const glm::mat4& projection, glm::vec2 jitter, int width, int height);

// A 32-bit hash of up to four integers (deterministic, platform independent): per-frame random numbers.
std::uint32_t hash_u32(std::uint32_t a, std::uint32_t b = 0, std::uint32_t c = 0, std::uint32_t d = 0);

}  // namespace temporal
