// Motion-compensated history fetch with disocclusion detection (seed 000 section 3.2 and Figure 3).
//
// The surface seen at full-resolution pixel (X, Y) was at p_prev = (X + 0.5, Y + 0.5) + motion in the
// previous frame (docs/conventions.md). The history is sampled there bilinearly; each of the four bilinear
// taps is tested on its own and dropped when
//   - it lies outside the image,
//   - its material id differs from the current pixel's id (contact points, Figure 3 right), or
//   - its depth differs from the current depth by more than `depth_tolerance` relative to the larger of
//     the two (warped-depth comparison [Nehab et al. 2007]; the current depth stands for the expected
//     previous depth since the G-buffer carries no depth velocity).
// The surviving taps are renormalised; the fetch is a miss (disocclusion) when none survives. Dropping
// taps one by one keeps a background pixel next to a silhouette from averaging in the foreground.
#pragma once

#include <cmath>
#include <cstdint>

namespace temporal::upsample {

// Default relative depth tolerance of the disocclusion test (not given by the paper).
inline constexpr float kDisocclusionDepthTolerance = 0.05f;

// Bilinear footprint of a motion-compensated position in a width x height image: top-left tap (x0, y0),
// weights of the four taps (x0,y0), (x0+1,y0), (x0,y0+1), (x0+1,y0+1).
struct BilinearTaps {
  int x0 = 0, y0 = 0;
  float w[4] = {0, 0, 0, 0};
};

// Taps for pixel (X, Y) moved by (mx, my) pixels: the sample point in pixel-centre coordinates is
// (X + mx, Y + my).
inline BilinearTaps bilinear_taps(int X, int Y, float mx, float my) {
  const float u = float(X) + mx, v = float(Y) + my;
  const float fu = std::floor(u), fv = std::floor(v);
  BilinearTaps t;
  t.x0 = int(fu);
  t.y0 = int(fv);
  const float ax = u - fu, ay = v - fv;
  t.w[0] = (1 - ax) * (1 - ay);
  t.w[1] = ax * (1 - ay);
  t.w[2] = (1 - ax) * ay;
  t.w[3] = ax * ay;
  return t;
}

// Whether a previous-frame sample (depth z_prev, id id_prev) is the same surface as the current pixel.
inline bool same_surface(float z, std::uint32_t id, float z_prev, std::uint32_t id_prev, float depth_tolerance,
                         bool use_ids) {
  if (use_ids && id != id_prev) return false;
  const float m = std::fmax(z, z_prev);
  return std::abs(z - z_prev) <= depth_tolerance * m;
}

}  // namespace temporal::upsample
