// Max-MIP pyramid that remembers where each maximum is (seed 004 section 6, Figure 6).
//
// Level 0 is a scalar field (e.g. the motion-flow gradient magnitude). Level l texel (i, j) holds the
// maximum of a 2^l x 2^l block of level-0 pixels and the pixel where that maximum occurs, so a grid vertex
// finds the strongest discontinuity of its own block in one lookup at level log2(cell size).
//
// Blocks may be shifted by `offset` pixels: level-l texel (i, j) covers pixels
// [i*2^l - offset, (i+1)*2^l - offset) x [j*2^l - offset, (j+1)*2^l - offset). With offset = cell/2 each block
// is centred on a grid vertex (i*cell, j*cell), so the neighbourhoods of neighbouring vertices never overlap
// and together cover the image (seed 004 section 6). Pixels outside the image count as -infinity.
#pragma once

#include <cstdint>
#include <vector>

namespace temporal::morph {

class MaxPyramid {
 public:
  struct Entry {
    float value = 0.0f;  // maximum of the block (-infinity when the block lies outside the image)
    int x = -1;          // pixel of the maximum (-1 when the block lies outside the image)
    int y = -1;
  };

  // Builds levels 1..levels from `values` (width x height floats, row-major, not copied: it must outlive
  // the queries only through build(); the pyramid stores its own levels). Reuses its buffers between
  // calls, so a pyramid kept across frames allocates once. Runs in parallel over rows.
  void build(const float* values, int width, int height, int levels, int offset);

  // The maximum of level `level` (1..levels) texel (i, j) and where it is. Ties resolve to the first pixel
  // in raster order of the 2x2 children (callers that prefer the nearest maximum add a small bias).
  Entry at(int level, int i, int j) const;

  int levels() const { return static_cast<int>(value_.size()); }
  int level_width(int level) const { return widths_[level - 1]; }
  int level_height(int level) const { return heights_[level - 1]; }

 private:
  int width_ = 0;
  std::vector<std::vector<float>> value_;         // per level >= 1: maxima
  std::vector<std::vector<std::int32_t>> index_;  // per level >= 1: pixel index y*width+x of the max, -1 none
  std::vector<int> widths_, heights_;
};

}  // namespace temporal::morph
