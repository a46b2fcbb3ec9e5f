// Blur through a MIP pyramid (seed 004 section 6, "Blur"): levels built with the recursive 3-tap binomial
// filter [1 2 1]/4 (separable, then decimation by 2), read back at full resolution at a higher level with
// tri-cubic reconstruction. This approximates a Gaussian blur at a cost independent of its width.
//
// Geometry: level l texel i is centred on full-resolution pixel i * 2^l (its centre at x = i*2^l + 0.5 in
// continuous pixel coordinates): decimation keeps the even samples of the filtered level, so the low-pass
// image is not shifted. The effective kernel of level l read back with the cubic B-spline has a variance of
// about (4^l - 1)/6 + 4^l/3 px^2 (level 2: sigma ~ 2.8 px).
//
// "Tri-cubic": cubic B-spline in x and in y, and, for a fractional level, a cubic (smooth-step) blend
// between the two neighbouring levels.
#pragma once

#include <span>
#include <vector>

namespace temporal::morph {

// The reconstruction's taps of level `level` (n texels along the axis) for the full-resolution samples 0..full-1:
// per sample 4 texel indices (clamped to [0, n-1]) and their 4 cubic B-spline weights. BlurPyramid::reconstruct
// reads them; the GPU kernel of didyk uploads the same table, so both use the same weights bit for bit.
void blur_pyramid_taps(int full, int n, int level, std::vector<int>& index, std::vector<float>& weight);

class BlurPyramid {
 public:
  // Builds levels 1..levels of every plane (each width x height floats). Level 0 is the input itself and is
  // referenced, not copied: the planes must stay alive while reconstruct() is used. Buffers are reused.
  void build(std::span<const float* const> planes, int width, int height, int levels);

  // Writes level `level` (0..levels, fractional allowed) reconstructed at full resolution into `out`
  // (one plane per input plane, width x height). Level 0 copies the input. Parallel over rows.
  void reconstruct(float level, std::span<float* const> out) const;

  int levels() const { return levels_; }
  int level_width(int level) const { return widths_[level]; }
  int level_height(int level) const { return heights_[level]; }
  // Level `level` (>= 1) of plane `plane`.
  const float* level_plane(int level, int plane) const;

 private:
  void reconstruct_level(int level, float* const* out, float weight, bool accumulate) const;

  int levels_ = 0;
  int channels_ = 0;
  std::vector<const float*> base_;
  std::vector<int> widths_, heights_;            // per level 0..levels
  std::vector<std::vector<float>> data_;         // per level >= 1: channels_ planes back to back
  mutable std::vector<float> scratch_;
};

}  // namespace temporal::morph
