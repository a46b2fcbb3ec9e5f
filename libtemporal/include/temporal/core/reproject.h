// Reprojection: the one motion-compensated fetch of the previous frame that every method and metric uses
// (docs/conventions.md, "Motion vectors" and "Reprojection").
//
// Coordinates. Here a pixel's centre is at integer coordinates: current pixel (x, y) fetches its history at
//     f = (x + motion.X, y + motion.Y)
// in the previous image (motion points from the current pixel to where its surface was, in pixels, jitter removed;
// in the image-area convention of docs/conventions.md that is p_prev = (x + 0.5, y + 0.5) + motion).
//
// The rules, defined once here and nowhere else:
//  - Off screen: f is off screen unless its pixel-area position lies inside the previous image,
//    -0.5 <= f.x < width - 0.5 and -0.5 <= f.y < height - 0.5 (NaN or infinite motion is off screen).
//  - Bilinear fetch: the four pixel centres around f; within half a pixel of the border the outside taps repeat
//    the edge (equivalently: they are dropped and the others renormalised). Catmull-Rom (4x4) for methods that
//    ask for it (TAA's history, Karis 2014).
//  - Disocclusion ("not the same surface"): a previous-frame sample q is the same surface as the current pixel p
//    when the material ids match (when ids are used) and |z_exp(p) - z_prev(q)| <= tolerance * max(z_exp(p),
//    z_prev(q)), with z linear view depth and tolerance 5 % by default. z_exp is the depth the surface is
//    expected to have had in the previous frame: the current depth unless the caller has a better estimate.
//    Each of the four bilinear taps is tested on its own; the taps that fail are dropped and the others
//    renormalised, so a background pixel beside a silhouette never averages in the foreground. The fetch is a
//    miss (disoccluded) when the surviving weight is below 1e-3 or f is off screen.
// Methods whose paper defines its own validity test (Drobot's reprojection cache, Listing 7.2; PHLM's and TAA's
// neighbourhood box) apply it on top of these rules; metrics use exactly these rules, so a metric and the method
// it judges agree on which pixels have history.
#pragma once

#include <algorithm>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <span>
#include <vector>

namespace temporal::reproject {

// --- Scalar primitives (inline: methods call them once per pixel inside their row loops) ----------------------

// The off-screen rule (above). False for NaN.
inline bool on_screen(float fx, float fy, int width, int height) {
  return fx >= -0.5f && fy >= -0.5f && fx < float(width) - 0.5f && fy < float(height) - 0.5f;
}

// The four taps and weights of a bilinear fetch at f, edge taps repeated. Weights sum to 1; a fetch exactly at a
// pixel centre has weights (1, 0, 0, 0) and returns that pixel bit for bit, so a static scene reprojects exactly.
struct Bilinear {
  std::size_t i00, i10, i01, i11;  // plane offsets
  float w00, w10, w01, w11;

  template <typename T>
  float operator()(const T* plane) const {
    return w00 * float(plane[i00]) + w10 * float(plane[i10]) + w01 * float(plane[i01]) + w11 * float(plane[i11]);
  }
};

inline Bilinear bilinear(float fx, float fy, int width, int height) {
  const float x0f = std::floor(fx), y0f = std::floor(fy);
  const float tx = fx - x0f, ty = fy - y0f;
  const int x0 = std::clamp(int(x0f), 0, width - 1), x1 = std::clamp(int(x0f) + 1, 0, width - 1);
  const int y0 = std::clamp(int(y0f), 0, height - 1), y1 = std::clamp(int(y0f) + 1, 0, height - 1);
  const auto w = std::size_t(width);
  Bilinear b;
  b.i00 = std::size_t(y0) * w + std::size_t(x0);
  b.i10 = std::size_t(y0) * w + std::size_t(x1);
  b.i01 = std::size_t(y1) * w + std::size_t(x0);
  b.i11 = std::size_t(y1) * w + std::size_t(x1);
  b.w00 = (1.0f - tx) * (1.0f - ty);
  b.w10 = tx * (1.0f - ty);
  b.w01 = (1.0f - tx) * ty;
  b.w11 = tx * ty;
  return b;
}

// Index of the pixel nearest to f, clamped to the image (for data that must not be blended: ids).
inline std::size_t nearest(float fx, float fy, int width, int height) {
  const int x = std::clamp(int(std::lround(fx)), 0, width - 1);
  const int y = std::clamp(int(std::lround(fy)), 0, height - 1);
  return std::size_t(y) * std::size_t(width) + std::size_t(x);
}

// Catmull-Rom cubic weights (B = 0, C = 0.5 of Mitchell-Netravali) of the taps at offsets -1, 0, 1, 2 from
// floor(f), for t = f - floor(f). They sum to 1; two are negative for 0 < t < 1, so a Catmull-Rom fetch can
// overshoot its taps (TAA clips the result to the neighbourhood box).
inline void catmull_rom_weights(float t, float w[4]) {
  const float t2 = t * t, t3 = t2 * t;
  w[0] = 0.5f * (-t3 + 2.0f * t2 - t);
  w[1] = 0.5f * (3.0f * t3 - 5.0f * t2 + 2.0f);
  w[2] = 0.5f * (-3.0f * t3 + 4.0f * t2 + t);
  w[3] = 0.5f * (t3 - t2);
}

// A 4x4 Catmull-Rom fetch at f with edge taps repeated: rows, columns and separable weights, shared by the
// channels of one pixel.
struct CatmullRom {
  std::size_t row[4];  // offsets of the four rows
  int col[4];          // the four columns
  float wx[4], wy[4];

  template <typename T>
  float operator()(const T* plane) const {
    float sum = 0.0f;
    for (int j = 0; j < 4; ++j) {
      const T* r = plane + row[j];
      const float h = wx[0] * float(r[col[0]]) + wx[1] * float(r[col[1]]) + wx[2] * float(r[col[2]]) +
                      wx[3] * float(r[col[3]]);
      sum += wy[j] * h;
    }
    return sum;
  }
};

inline CatmullRom catmull_rom(float fx, float fy, int width, int height) {
  const float x0f = std::floor(fx), y0f = std::floor(fy);
  CatmullRom c;
  catmull_rom_weights(fx - x0f, c.wx);
  catmull_rom_weights(fy - y0f, c.wy);
  const int x0 = int(x0f), y0 = int(y0f);
  for (int k = 0; k < 4; ++k) {
    c.col[k] = std::clamp(x0 - 1 + k, 0, width - 1);
    c.row[k] = std::size_t(std::clamp(y0 - 1 + k, 0, height - 1)) * std::size_t(width);
  }
  return c;
}

// Default relative depth tolerance of the disocclusion test. Seed 000 (section 3.2) compares warped depths
// without giving a threshold; 5 % of the depth keeps a sloped surface moving a few pixels per frame (whose
// bilinear taps differ in depth by the slope) while rejecting any foreground/background pair of the built-in
// scenes (docs/conventions.md, "Reprojection").
inline constexpr float kDepthTolerance = 0.05f;
// Relative tolerance when z_exp is the warped depth (G-buffer layer prevDepth.Z: the depth the current surface
// point had in the previous frame, seed 000 section 3.2). Motion along the view axis no longer enters, so the
// tolerance only has to cover the surface's own depth change between the fetch position and its bilinear taps
// (up to one pixel away in x and y: the slope of the previous depth over one pixel) and float rounding. For a plane
// at angle theta from the view direction the relative change per pixel is about tan(theta) x (the pixel's angle),
// so a relative tolerance keeps taps up to some theta; measured on walkers, tower and fan at 320x256
// (docs/upsample-st.md, "Warped depth (issue 15 item 5)"): 0.5 % and 1 % drop the taps of the tower's sloped
// walls under its moving camera (-0.4 / -0.1 dB), 2 % is level there and still gains on walkers (+0.06 / +0.22 dB).
inline constexpr float kWarpedDepthTolerance = 0.02f;
// A fetch whose surviving bilinear weight is below this is a miss (numerically: no tap passed).
inline constexpr float kMinHitWeight = 1e-3f;

// The disocclusion test and what it compares.
struct SurfaceTest {
  float depth_tolerance = kDepthTolerance;  // relative, see above
  bool use_ids = true;                      // also require equal material ids
};

// Whether a previous-frame sample (z_prev, id_prev) is the same surface as the current pixel (expected previous
// depth z, id).
inline bool same_surface(float z, std::uint32_t id, float z_prev, std::uint32_t id_prev, const SurfaceTest& test) {
  if (test.use_ids && id != id_prev) return false;
  return std::abs(z - z_prev) <= test.depth_tolerance * std::fmax(z, z_prev);
}

// floor() for |x| < 2^31, written so that loops using it vectorise (GCC does not vectorise std::floor without
// -fno-trapping-math; the truncating conversion does). Same value as std::floor (up to the sign of 0).
inline float floor_vec(float x) {
  const float t = float(int(x));
  return t > x ? t - 1.0f : t;
}

// --- Row kernels (vectorised; used by the upsampling methods and by the metrics) -----------------------------

// The history taps of one row of W pixels: tap indices q[j][x] into the previous frame's planes and renormalised
// bilinear weights w[j][x] of the four taps that pass the rules; all weights 0 and hit[x] = 0 on a miss.
struct HistoryRow {
  std::vector<int> q[4];
  std::vector<float> w[4];
  std::vector<float> hit;
  // Runs of the row, in order, covering [0, W): {x0, x1, base}; base >= 0: the taps are the image-aligned 2x2
  // block at a constant offset (q0 = base + x, q1 = q0 + 1, q2 = q0 + W, q3 = q2 + 1), read with contiguous
  // loads (camera pans, static regions); base = -1: gathered through q.
  struct Segment {
    int x0, x1, base;
  };
  std::vector<Segment> segments;
  std::vector<int> offset, aligned;  // scratch: q0 - x, and 1 where the taps form the aligned block
  std::vector<std::uint8_t> breaks;  // scratch of build_segments: 1 where a run of equal aligned offsets ends
  void resize(int W);
};

// What a reprojection reads: the current frame's motion and geometry and the previous frame's geometry, whole
// width x height planes. Null motion means none. Null `z` or `prev_z` turns the disocclusion test off (only the
// off-screen rule applies, e.g. a G-buffer with motion but no depth); null `id` or `prev_id` skips the id test.
struct Frames {
  int width = 0, height = 0;
  const float* motion_x = nullptr;
  const float* motion_y = nullptr;
  const float* z = nullptr;                // expected previous depth of the current pixels: the current depth, or
                                           // the warped depth (prevDepth.Z) with kWarpedDepthTolerance
  const std::uint32_t* id = nullptr;       // current material ids
  const float* prev_z = nullptr;           // previous frame's depth
  const std::uint32_t* prev_id = nullptr;  // previous frame's material ids
  SurfaceTest test;
};

// Sets what the disocclusion test compares the previous depth with (seed 000 section 3.2): the warped depth
// (G-buffer layer prevDepth.Z, the depth the surface point had in the previous frame) at `warped_tolerance` when
// the caller has it, else the current depth at the tolerance already in `frames.test`. The one place that rule lives.
inline void expect_depth(Frames& frames, const float* depth, const float* warped_depth,
                         float warped_tolerance = kWarpedDepthTolerance) {
  frames.z = warped_depth ? warped_depth : depth;
  if (warped_depth) frames.test.depth_tolerance = warped_tolerance;
}

// Fills `h` for row y with the rules above. Allocates only when the width grows.
void reproject_row(const Frames& frames, int y, HistoryRow& h);

// Splits a row whose q are set into HistoryRow::segments (runs of at least 16 aligned pixels at one offset are
// contiguous segments; everything between them one gather segment). `offset` and `aligned` must be filled.
// Exposed for kernels that build their own q (herzog's gradient cells).
void build_segments(HistoryRow& h, int width);

// Gathers n >= 1 previous-frame planes (four at a time) with the taps of `h` into out[i][0..W):
// out = sum_j w[j] prev[q[j]] (0 on a miss: callers test h.hit).
void gather_row(const HistoryRow& h, const float* const* prev, float* const* out, int n, int width);

// reproject_row, then gather_row of n >= 1 planes, in one pass over the row: the same values in out and h.hit.
// Up to four planes, the aligned runs (HistoryRow::segments) test and gather in one loop that never stores their
// weights: h.q and h.w then hold the taps of the gather runs only, so a caller that needs the weights of every
// pixel (to gather more planes later) calls the two steps instead. More than four planes: the two steps. Its runs
// are found 16 pixels at a time (reproject_kernels.inc, block_segments; in the v3 and v4 copies one vector of 8 or
// 16 pixels at a time while they are fetched, verified_runs), so h.segments may split the row differently from
// build_segments; the values do not depend on the split.
void reproject_gather_row(const Frames& frames, int y, HistoryRow& h, const float* const* prev, float* const* out,
                          int n);

// --- Whole planes (metrics) --------------------------------------------------------------------------------

// out[k] = previous[k] fetched for every pixel with the rules above, NaN where the fetch is a miss (off screen or
// disoccluded), so that any metric using it drops the pixel. A NaN in `previous` propagates to the pixels that
// fetch it. Parallel over rows.
void warp_planes(const Frames& frames, std::span<const float* const> previous, std::span<float* const> out);

}  // namespace temporal::reproject
