// Grid morphing of seed 004 (sections 5.1 "Morphing" and 6 "Morphing"). The paper draws the grid with
// OpenGL; this is the same operation on the CPU: a closed, connected grid of triangles, fold-overs allowed,
// depth test on the original frame's depth, pixel centres sampled with a top-left rule so that every pixel is
// covered by exactly one of two triangles sharing an edge.
#include "temporal/morph/grid_warp.h"

#include "temporal/core/isa.h"
#include "temporal/core/parallel.h"
#include "temporal/core/reproject.h"

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include <algorithm>
#include <cmath>
#include <limits>

namespace temporal::morph {

float eye_tracking_factor(float degrees_per_second) {
  // Section 6: f(70) = 1 (perfect tracking), f(90) = 0 (no tracking), cubic with f'(70) = f'(90) = 0.
  if (degrees_per_second <= 70.0f) return 1.0f;
  if (degrees_per_second >= 90.0f) return 0.0f;
  const float t = (degrees_per_second - 70.0f) / 20.0f;
  return 1.0f - t * t * (3.0f - 2.0f * t);
}

void GridBuilder::build(const float* motion_x, const float* motion_y, const float* depth, int width, int height,
                        const GridOptions& options, SnappedGrid& grid) {
  const int cell = options.cell;
  int level = 0;
  while ((1 << level) < cell) ++level;
  grid.width = width;
  grid.height = height;
  grid.cell = cell;
  grid.nx = (width + cell - 1) / cell + 1;
  grid.ny = (height + cell - 1) / cell + 1;
  const std::size_t nv = std::size_t(grid.nx) * std::size_t(grid.ny);
  grid.x.resize(nv);
  grid.y.resize(nv);
  grid.mx.resize(nv);
  grid.my.resize(nv);
  grid.border.resize(nv);
  grid.snap_strength.resize(nv);

  const int half = cell / 2;
  if (options.snap) {
    // Discontinuity strength of the pixel corner (x+1, y+1): the larger motion difference across the two
    // diagonals of the 2x2 pixels around it (any edge through the 2x2 block separates one diagonal pair).
    // A small bias of 1e-3 px per cell of distance breaks ties (a straight edge has equal strength along its
    // whole length) towards the regular vertex position, so grids stay as regular as the flow allows.
    score_.resize(std::size_t(width) * std::size_t(height));
    const float bias = 1e-3f / float(cell);
    parallel_rows(height, [&](int y0, int y1) {
      for (int y = y0; y < y1; ++y) {
        float* s = score_.data() + std::size_t(y) * std::size_t(width);
        if (y + 1 >= height) {
          for (int x = 0; x < width; ++x) s[x] = -std::numeric_limits<float>::infinity();
          continue;
        }
        const float* ax = motion_x + std::size_t(y) * std::size_t(width);
        const float* ay = motion_y + std::size_t(y) * std::size_t(width);
        const float* bx = ax + width;
        const float* by = ay + width;
        const float vy = float(((y + half) / cell) * cell - (y + 1));
        for (int x = 0; x + 1 < width; ++x) {
          const float d1x = ax[x] - bx[x + 1], d1y = ay[x] - by[x + 1];
          const float d2x = ax[x + 1] - bx[x], d2y = ay[x + 1] - by[x];
          const float g = std::sqrt(std::max(d1x * d1x + d1y * d1y, d2x * d2x + d2y * d2y));
          const float vx = float(((x + half) / cell) * cell - (x + 1));
          s[x] = g - bias * std::sqrt(vx * vx + vy * vy);
        }
        s[width - 1] = -std::numeric_limits<float>::infinity();
      }
    });
    pyramid_.build(score_.data(), width, height, level, half);
  }

  const float speed_scale = options.pixels_per_degree > 0.0f ? float(options.fps) / options.pixels_per_degree : 0.0f;
  parallel_rows(grid.ny, [&](int j0, int j1) {
    for (int j = j0; j < j1; ++j) {
      for (int i = 0; i < grid.nx; ++i) {
        const std::size_t v = std::size_t(j) * std::size_t(grid.nx) + std::size_t(i);
        int X = std::min(i * cell, width);
        int Y = std::min(j * cell, height);
        const bool border = i == 0 || j == 0 || i == grid.nx - 1 || j == grid.ny - 1;
        grid.border[v] = border ? 1 : 0;
        grid.snap_strength[v] = 0.0f;
        if (border) {
          // Section 5.1: border vertices keep their place, so no undefined region enters the image.
          grid.x[v] = float(X);
          grid.y[v] = float(Y);
          grid.mx[v] = 0.0f;
          grid.my[v] = 0.0f;
          continue;
        }
        if (options.snap) {
          const MaxPyramid::Entry e = pyramid_.at(level, i, j);
          if (e.x >= 0 && e.value >= options.snap_threshold) {
            X = e.x + 1;
            Y = e.y + 1;
            grid.snap_strength[v] = e.value;
          }
        }
        grid.x[v] = float(X);
        grid.y[v] = float(Y);
        // The vertex sits on a pixel corner between up to four pixels, possibly on both sides of a motion
        // discontinuity: it follows the nearest surface (smallest depth), so foreground silhouettes move
        // rigidly and the background side of the cell stretches over the disocclusion.
        int best = -1;
        float best_depth = std::numeric_limits<float>::infinity();
        for (int dy = -1; dy <= 0; ++dy) {
          for (int dx = -1; dx <= 0; ++dx) {
            const int px = std::clamp(X + dx, 0, width - 1), py = std::clamp(Y + dy, 0, height - 1);
            const int k = py * width + px;
            const float z = depth ? depth[k] : 0.0f;
            if (best < 0 || z < best_depth) {
              best = k;
              best_depth = z;
            }
          }
        }
        float mx = motion_x[best], my = motion_y[best];
        if (!std::isfinite(mx) || !std::isfinite(my)) mx = my = 0.0f;
        if (speed_scale > 0.0f) {
          const float f = eye_tracking_factor(std::sqrt(mx * mx + my * my) * speed_scale);
          mx *= f;
          my *= f;
        }
        grid.mx[v] = mx;
        grid.my[v] = my;
      }
    }
  }, 1);
}

void extrapolate_vertices(const SnappedGrid& grid, float t, std::vector<float>& tx, std::vector<float>& ty) {
  const std::size_t n = std::size_t(grid.vertex_count());
  tx.resize(n);
  ty.resize(n);
  // p_prev = p + motion, so under linear motion the point is at p - t * motion a fraction t of a frame later.
  for (std::size_t v = 0; v < n; ++v) {
    tx[v] = grid.x[v] - t * grid.mx[v];
    ty[v] = grid.y[v] - t * grid.my[v];
  }
}

namespace {

inline double cross(double ax, double ay, double bx, double by) { return ax * by - ay * bx; }

}  // namespace

void cell_distortion(const SnappedGrid& grid, std::span<const float> tx, std::span<const float> ty,
                     std::vector<float>& distortion) {
  const int cx = grid.nx - 1, cy = grid.ny - 1;
  distortion.resize(std::size_t(cx) * std::size_t(cy));
  const float inv_cell = 1.0f / float(grid.cell);
  parallel_rows(cy, [&](int j0, int j1) {
    for (int j = j0; j < j1; ++j) {
      for (int i = 0; i < cx; ++i) {
        const int a = j * grid.nx + i, b = a + 1, c = a + grid.nx, d = c + 1;
        auto edge = [&](int p, int q) {
          const float ex = (tx[q] - tx[p]) - (grid.x[q] - grid.x[p]);
          const float ey = (ty[q] - ty[p]) - (grid.y[q] - grid.y[p]);
          return std::sqrt(ex * ex + ey * ey);
        };
        // Measured relative to the cell size: a relative measure per edge would explode on the one-pixel
        // edges that snapping can create.
        float dist = std::max({edge(a, b), edge(a, c), edge(b, d), edge(c, d), edge(a, d)}) * inv_cell;
        // A triangle whose orientation flips (or collapses) is a fold-over: content is being covered or torn.
        auto area = [&](const float* xs, const float* ys, int p, int q, int r) {
          return cross(double(xs[q]) - xs[p], double(ys[q]) - ys[p], double(xs[r]) - xs[p], double(ys[r]) - ys[p]);
        };
        const double s1 = area(grid.x.data(), grid.y.data(), a, b, d), s2 = area(grid.x.data(), grid.y.data(), a, d, c);
        const double t1 = area(tx.data(), ty.data(), a, b, d), t2 = area(tx.data(), ty.data(), a, d, c);
        if (s1 * t1 <= 0.0 && std::abs(s1) > 1e-9) dist = kFoldDistortion;
        if (s2 * t2 <= 0.0 && std::abs(s2) > 1e-9) dist = kFoldDistortion;
        distortion[std::size_t(j) * std::size_t(cx) + std::size_t(i)] = std::min(dist, kFoldDistortion);
      }
    }
  }, 1);
}

void cells_to_vertices(const SnappedGrid& grid, std::span<const float> cell_values, std::vector<float>& vertex_values) {
  const int cx = grid.nx - 1, cy = grid.ny - 1;
  vertex_values.resize(std::size_t(grid.vertex_count()));
  for (int j = 0; j < grid.ny; ++j) {
    for (int i = 0; i < grid.nx; ++i) {
      float m = 0.0f;
      for (int dj = -1; dj <= 0; ++dj) {
        for (int di = -1; di <= 0; ++di) {
          const int ci = i + di, cj = j + dj;
          if (ci < 0 || cj < 0 || ci >= cx || cj >= cy) continue;
          m = std::max(m, cell_values[std::size_t(cj) * std::size_t(cx) + std::size_t(ci)]);
        }
      }
      vertex_values[std::size_t(j) * std::size_t(grid.nx) + std::size_t(i)] = m;
    }
  }
}

namespace {

constexpr int kBand = 16;  // rows per raster band (the unit of parallel work)
constexpr std::size_t kMaxAttributes = 8;

// The three vertices of triangle t: each cell is split along its top-left to bottom-right diagonal.
inline void corners(const SnappedGrid& grid, int t, int out[3]) {
  const int cells_x = grid.nx - 1;
  const int c = t >> 1;
  const int a = (c / cells_x) * grid.nx + (c % cells_x);
  if ((t & 1) == 0) {
    out[0] = a; out[1] = a + 1; out[2] = a + grid.nx + 1;
  } else {
    out[0] = a; out[1] = a + grid.nx + 1; out[2] = a + grid.nx;
  }
}

// The band kernel copies, one per instruction set (temporal/core/isa.h). v3 and v4 may contract the edge
// functions' and the interpolations' multiply-adds into FMAs (v2 has none): a pixel centre within rounding of a
// shared edge can fall to the other triangle, and interpolated values differ in the last bits
// (tests/core/isa_test.cpp bounds both); v3 and v4 are bit-identical.
#define TEMPORAL_ISA_FILE "grid_warp_kernels.inc"
#include "temporal/core/isa_copies.inc"

void draw_bands_copy(const SnappedGrid& grid, std::span<const float> tx, std::span<const float> ty,
                     const GridRaster& raster, float* zbuffer, const std::vector<std::vector<std::int32_t>>& bins) {
  TEMPORAL_ISA_CALL(copy, return copy::draw_bands(grid, tx, ty, raster, zbuffer, bins))
}

}  // namespace

void GridRasterizer::draw(const SnappedGrid& grid, std::span<const float> tx, std::span<const float> ty,
                          const GridRaster& raster) {
  if (raster.attributes.size() > kMaxAttributes) return;  // documented limit (never reached by the callers)
  const int h = grid.height;
  const int bands = (h + kBand - 1) / kBand;
  const int triangles = 2 * grid.cell_count();
  // The z-buffer doubles as the coverage mask (infinity: no fragment yet).
  zbuffer_.resize(std::size_t(grid.width) * std::size_t(h));
  bins_.resize(std::size_t(bands));
  for (auto& b : bins_) b.clear();
  // Binning by bands of target rows, in triangle order, so each band draws its triangles in the same order
  // as a serial rasteriser would: the result does not depend on the thread count.
  for (int t = 0; t < triangles; ++t) {
    int v[3];
    corners(grid, t, v);
    const float y0 = std::min({ty[v[0]], ty[v[1]], ty[v[2]]});
    const float y1 = std::max({ty[v[0]], ty[v[1]], ty[v[2]]});
    const int r0 = std::max(0, int(std::ceil(y0 - 0.5f)));
    const int r1 = std::min(h - 1, int(std::floor(y1 - 0.5f)));
    if (r1 < r0) continue;
    for (int b = r0 / kBand; b <= r1 / kBand; ++b) bins_[std::size_t(b)].push_back(t);
  }
  draw_bands_copy(grid, tx, ty, raster, zbuffer_.data(), bins_);
}

void draw_grid_lines(const SnappedGrid& grid, std::span<const float> tx, std::span<const float> ty, float* plane) {
  const int w = grid.width, h = grid.height;
  auto line = [&](int a, int b) {
    const float dx = tx[b] - tx[a], dy = ty[b] - ty[a];
    const int steps = int(std::ceil(std::max(std::abs(dx), std::abs(dy)))) * 2 + 1;
    for (int s = 0; s <= steps; ++s) {
      const float f = float(s) / float(steps);
      const int x = std::clamp(int(std::floor(tx[a] + f * dx)), 0, w - 1);
      const int y = std::clamp(int(std::floor(ty[a] + f * dy)), 0, h - 1);
      plane[std::size_t(y) * std::size_t(w) + std::size_t(x)] = 1.0f;
    }
  };
  for (int j = 0; j < grid.ny; ++j) {
    for (int i = 0; i < grid.nx; ++i) {
      const int a = j * grid.nx + i;
      if (i + 1 < grid.nx) line(a, a + 1);
      if (j + 1 < grid.ny) line(a, a + grid.nx);
    }
  }
}

}  // namespace temporal::morph
