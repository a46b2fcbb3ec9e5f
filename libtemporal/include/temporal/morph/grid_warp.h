// Grid morphing of seed 004 (sections 5.1 and 6): a regular grid whose vertices are snapped to the strongest
// motion-flow discontinuity of their own cell, moved by the (extrapolated) flow, and rasterised on the CPU
// with a depth test on the original frame's depth, fold-overs allowed.
//
// Coordinates are continuous pixel coordinates of docs/conventions.md: x right, y down, pixel (x, y) covers
// [x, x+1) x [y, y+1). Grid vertices sit on pixel corners. Motion follows the conventions too: motion(p) is
// the offset in pixels from p to where the surface seen at p was in the previous frame (p_prev = p + motion).
#pragma once

#include "temporal/morph/max_pyramid.h"

#include <cstdint>
#include <span>
#include <vector>

namespace temporal::morph {

struct GridOptions {
  int cell = 8;                 // cell size in pixels, a power of two in [2, 32] (paper: 8x8)
  bool snap = true;             // snap vertices to motion discontinuities (false: regular grid, for tests)
  float snap_threshold = 0.5f;  // px: a cell whose largest motion difference is below this is not snapped
  // Eye-tracking limit (seed 004 section 6): vertex motion is scaled by eye_tracking_factor(speed) with
  // speed = |motion| * fps / pixels_per_degree in deg/s. pixels_per_degree <= 0 disables the limit.
  float pixels_per_degree = 0.0f;
  double fps = 40.0;            // frames per second of the rendered (input) sequence
};

// The snapped grid of one rendered frame. Vertex (i, j) is element j * nx + i.
struct SnappedGrid {
  int width = 0, height = 0;  // image size, pixels
  int cell = 8;
  int nx = 0, ny = 0;         // vertices per row and per column (ceil(size / cell) + 1)
  std::vector<float> x, y;    // snapped source positions (also the texture coordinates), pixels
  std::vector<float> mx, my;  // vertex motion (conventions' sign, eye-tracking damping applied), pixels
  std::vector<std::uint8_t> border;  // 1 for vertices on the image border: never snapped, never moved
  std::vector<float> snap_strength;  // motion difference (px) at the snapped location, 0 when not snapped

  int vertex_count() const { return nx * ny; }
  int cell_count() const { return (nx - 1) * (ny - 1); }
};

// Seed 004's cubic smooth-step eye-tracking limit: 1 up to 70 deg/s, 0 from 90 deg/s, f'(70) = f'(90) = 0.
float eye_tracking_factor(float degrees_per_second);

// Builds SnappedGrid from the motion and depth planes of a G-buffer (width x height each). Keeps its scratch
// buffers (gradient plane, max-pyramid) between calls.
class GridBuilder {
 public:
  void build(const float* motion_x, const float* motion_y, const float* depth, int width, int height,
             const GridOptions& options, SnappedGrid& grid);

 private:
  std::vector<float> score_;
  MaxPyramid pyramid_;
};

// Vertex positions at fraction t of one input frame interval after the rendered frame (linear extrapolation
// of the flow: a point at p moves to p - t * motion; border vertices stay). Writes vertex_count() values.
void extrapolate_vertices(const SnappedGrid& grid, float t, std::vector<float>& tx, std::vector<float>& ty);

// Distortion of each cell of the warped grid: the largest change of an edge or diagonal vector relative to
// its length in the source, |(T_b - T_a) - (S_b - S_a)| / |S_b - S_a|; 0 for a rigid translation, and
// kFoldDistortion when a triangle of the cell flips orientation (fold-over) or collapses.
inline constexpr float kFoldDistortion = 4.0f;
void cell_distortion(const SnappedGrid& grid, std::span<const float> tx, std::span<const float> ty,
                     std::vector<float>& distortion);

// Per-vertex value from per-cell values: the maximum over the (up to four) cells sharing the vertex.
void cells_to_vertices(const SnappedGrid& grid, std::span<const float> cell_values, std::vector<float>& vertex_values);

// What GridRasterizer::draw samples and writes.
struct GridRaster {
  // Source planes sampled at the interpolated texture coordinate (width x height each) with the bilinear fetch of
  // temporal/core/reproject.h (edge taps repeated).
  std::span<const float* const> source;
  // Destination planes, one per source plane.
  std::span<float* const> target;
  // Per-vertex attributes (vertex_count() each, at most 8), interpolated linearly over each triangle into
  // attr_target.
  std::span<const float* const> attributes;
  std::span<float* const> attr_target;
  // Value written to attr_target[c] at pixels no triangle covers (default 0); targets get the source pixel.
  std::span<const float> attr_uncovered;
  // Selective blend (seed 004's selective blur): when >= 0, `source` holds 2C planes (C sharp, then C
  // blurred) and `target` C planes; each fragment writes sharp + a * (blurred - sharp), a = the interpolated
  // attribute `blend_attribute`, and samples the blurred planes only where a > 0.
  int blend_attribute = -1;
  // Skip triangles whose attributes are all 0 at their three vertices (only without source planes): their
  // pixels get attr_uncovered, as if uncovered. Saves drawing the whole grid for a sparse attribute.
  bool cull_zero_attributes = false;
  // Source depth (linear view depth, smaller is nearer), looked up at the nearest source pixel of every
  // fragment (reproject::nearest) for the depth test; nullptr disables the test (the last triangle drawn wins).
  const float* source_depth = nullptr;
};

// Scan-converts the grid's triangles (each cell split along the diagonal from its top-left to its bottom-right
// vertex) from source positions (grid.x, grid.y) to target positions (tx, ty). Pixel centres are sampled with
// a top-left fill rule, both orientations are drawn (fold-overs), and the depth test keeps the fragment with
// the nearest original depth. Pixels no triangle covers (a border-fixed grid covers every pixel; only
// degenerate triangles can leave one) get the source pixel and attr_uncovered. Parallel over bands of rows;
// scratch buffers are reused between calls.
class GridRasterizer {
 public:
  void draw(const SnappedGrid& grid, std::span<const float> tx, std::span<const float> ty, const GridRaster& raster);

 private:
  std::vector<float> zbuffer_;
  std::vector<std::vector<std::int32_t>> bins_;
};

// Draws the grid's edges (at target positions tx, ty) as 1.0 into `plane` (width x height), for the
// `debug.grid` layer.
void draw_grid_lines(const SnappedGrid& grid, std::span<const float> tx, std::span<const float> ty, float* plane);

}  // namespace temporal::morph
