// `didyk` (didyk.cpp, seed 004) as GLSL compute kernels: the same steps as the C++ reference of record, in the same
// order and with the same arithmetic where GLSL allows it (docs/gpu.md lists what differs and bounds it). Each pass
// below is its own program compiled from the one source with u_pass defined, so each keeps only its own code.
//
//   flow   - SCORE: the flow-discontinuity strength of every pixel corner (grid_warp.cpp, GridBuilder::build);
//            MAX: the max-pyramid with its argmax, one dispatch per level (max_pyramid.cpp, Figure 6);
//            VERTEX: snapping, the nearest surface's motion and the eye-tracking damping (section 6).
//   morph  - per in-between slot k: EXTRAPOLATE (p - k/N motion), CELL_DISTORTION (with the fold-over test in
//            double, as cell_distortion()), VERTEX_BLUR (cells_to_vertices, the smooth-step b_k of section 5.1
//            "Selective Blur", the blur sum B accumulated in slot order).
//   blur   - DISPLAY (v = lin^(1/g) with core/fast_math.h's log2/exp2 polynomials), BLUR_H / BLUR_V (the 3-tap
//            binomial pyramid, blur_pyramid.cpp), RECONSTRUCT (the tri-cubic read with the C++ tap table, uploaded
//            from blur_pyramid_taps), the blur sum rasterised on the source grid, COMPENSATE (section 5.1 "Gamma
//            Correction" and the dynamic-range rules, compensate_span in didyk.cpp).
//   morph  - the grid rasterised per slot with the depth test (grid_warp.cpp's GridRasterizer, below).
//
// The rasteriser. grid_warp.cpp scan-converts the triangles in order into a z-buffer: a fragment replaces the
// pixel's when its source depth is strictly smaller, so each pixel shows the fragment with the smallest
// (depth, triangle index); without a depth test the last triangle drawn wins. The kernels take that minimum
// with 32-bit atomics in passes over the triangles (one invocation per grid cell, its two triangles), each pass
// scan-converting exactly as the C++ does (edge functions in double, evaluated at the row start and stepped,
// top-left rule):
//   R_DEPTH  atomicMin of the fragment's depth as an order-preserving key (depth test only);
//   R_RANK   atomicMin of the triangle's rank (its index; without a depth test the reversed index) among the
//            fragments whose key equals the pixel's minimum;
//   R_WRITE  the one fragment whose rank equals the pixel's writes its attributes and its (blended) colour;
//   UNCOVERED the pixels no fragment reached get the source pixel and the uncovered attribute values.
// The winner is the C++ rasteriser's, so the outputs differ only by float rounding (see the tolerances).
#include "didyk_options.h"
#include "method_common.h"
#include "temporal/gpu/buffer.h"
#include "temporal/gpu/glsl.h"
#include "temporal/gpu/program.h"
#include "temporal/gpu/timer.h"
#include "temporal/morph/blur_pyramid.h"
#include "temporal/morph/gpu_methods.h"

#include <algorithm>
#include <bit>
#include <chrono>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <string>
#include <vector>

namespace temporal::morph {
namespace {

using namespace detail;

// The passes, one program each (u_pass is a constant in each program's source).
enum Pass : int {
  kScore = 0,
  kMax,
  kVertex,
  kExtrapolate,
  kCellDistortion,
  kVertexBlur,
  kDisplay,
  kBlurH,
  kBlurV,
  kReconstruct,
  kCompensate,
  kDebugH,
  kClear,
  kKeysClear,
  kRasterDepth,
  kRasterRank,
  kRasterWrite,
  kUncovered,
  kGridLines,
};

// Planes of `img` (binding 0, width x height each).
enum ImgPlane : int { kR = 0, kMX = 3, kMY = 4, kZ = 5, kV = 6, kL = 9, kLow = 12, kScorePlane = 15, kImgPlanes = 16 };
// Planes of `outb` (binding 1): the slot being produced, in the order R, G, B, then kMorphDebugLayers.
enum OutPlane : int { kGrid = 3, kDist = 4, kBlur = 5, kH = 6, kHp = 7, kOutPlanes = 8 };
// Planes of `grid` (binding 5, nx x ny each): the snapped grid, the blur sum B per vertex, then per slot k >= 1
// five planes (target x, y, blur strength b_k, vertex distortion, cell distortion).
enum GridPlane : int { kGX = 0, kGY, kGMX, kGMY, kGBorder, kGSnap, kGBSum, kGridFixed };
constexpr int kSlotPlanes = 5;

// The float constants of core/fast_math.h and grid_warp.h as bit patterns, so the GLSL uses the same floats as
// the C++ (a decimal literal could round differently in the driver's parser).
std::string constants() {
  std::string s;
  auto add = [&](const char* name, float v) {
    char line[96];
    std::snprintf(line, sizeof line, "#define %s uintBitsToFloat(0x%08xu)\n", name, std::bit_cast<std::uint32_t>(v));
    s += line;
  };
  add("FM_SQRT2", 1.41421356f);
  add("FM_THIRD", 1.0f / 3.0f);
  add("FM_FIFTH", 1.0f / 5.0f);
  add("FM_SEVENTH", 1.0f / 7.0f);
  add("FM_NINTH", 1.0f / 9.0f);
  add("FM_2_LN2", 2.88539008f);
  add("FM_LN2", 0.693147181f);
  add("FM_I6", 1.0f / 6.0f);
  add("FM_I24", 1.0f / 24.0f);
  add("FM_I120", 1.0f / 120.0f);
  add("FM_I720", 1.0f / 720.0f);
  add("FM_I5040", 1.0f / 5040.0f);
  add("FM_TINY", 1e-30f);
  add("LUM_R", 0.2126f);
  add("LUM_G", 0.7152f);
  add("LUM_B", 0.0722f);
  add("FOLD_DISTORTION", kFoldDistortion);
  s += "#define P_R " + std::to_string(kR) + "u\n#define P_MX " + std::to_string(kMX) + "u\n#define P_MY " +
       std::to_string(kMY) + "u\n#define P_Z " + std::to_string(kZ) + "u\n#define P_V " + std::to_string(kV) +
       "u\n#define P_L " + std::to_string(kL) + "u\n#define P_LOW " + std::to_string(kLow) + "u\n#define P_SCORE " +
       std::to_string(kScorePlane) + "u\n";
  s += "#define G_X " + std::to_string(kGX) + "u\n#define G_Y " + std::to_string(kGY) + "u\n#define G_MX " +
       std::to_string(kGMX) + "u\n#define G_MY " + std::to_string(kGMY) + "u\n#define G_BORDER " +
       std::to_string(kGBorder) + "u\n#define G_SNAP " + std::to_string(kGSnap) + "u\n#define G_BSUM " +
       std::to_string(kGBSum) + "u\n";
  char passes[512];
  std::snprintf(passes, sizeof passes,
                "#define PASS_SCORE %d\n#define PASS_MAX %d\n#define PASS_VERTEX %d\n#define PASS_EXTRAPOLATE %d\n"
                "#define PASS_CELL_DISTORTION %d\n#define PASS_VERTEX_BLUR %d\n#define PASS_DISPLAY %d\n"
                "#define PASS_BLUR_H %d\n#define PASS_BLUR_V %d\n#define PASS_RECONSTRUCT %d\n"
                "#define PASS_COMPENSATE %d\n#define PASS_DEBUG_H %d\n#define PASS_CLEAR %d\n"
                "#define PASS_KEYS_CLEAR %d\n#define PASS_R_DEPTH %d\n#define PASS_R_RANK %d\n"
                "#define PASS_R_WRITE %d\n#define PASS_UNCOVERED %d\n#define PASS_GRID_LINES %d\n",
                kScore, kMax, kVertex, kExtrapolate, kCellDistortion, kVertexBlur, kDisplay, kBlurH, kBlurV,
                kReconstruct, kCompensate, kDebugH, kClear, kKeysClear, kRasterDepth, kRasterRank, kRasterWrite,
                kUncovered, kGridLines);
  return s + passes;
}

constexpr const char* kDidykMain = R"(
#define NEG_INF uintBitsToFloat(0xff800000u)
#define POS_INF uintBitsToFloat(0x7f800000u)
const uint kEmpty = 0xffffffffu;

uniform uint u_n;        // pixels
uniform ivec2 u_grid;    // vertices per row and per column
uniform uint u_nv;       // vertices
uniform int u_cell, u_half;
uniform float u_bias;    // the snapping score's tie-break bias per pixel of distance (GridBuilder::build)
uniform int u_snap;
uniform float u_snap_threshold, u_speed_scale;
// A pyramid level: its size, the previous level's size, offsets into mp / bp, the block offset of level 1.
uniform ivec2 u_lsize, u_psize;
uniform uint u_off_prev, u_off_cur, u_src_off, u_src_plane, u_tmp_off, u_dst_off, u_taps_off;
uniform int u_first, u_offset, u_from_img, u_level0, u_accumulate;
uniform float u_weight;
// Per slot.
uniform float u_t, u_inv_cell, u_min_blur, u_dist_low, u_dist_high;
uniform uint u_slot;     // first grid plane of the slot
uniform int u_first_slot;
// Display and compensation.
uniform float u_gamma, u_inv_gamma;
uniform int u_compensate;
// Raster.
uniform uint u_tpx, u_tpy, u_attr0, u_attr1;  // grid planes (element offsets): target positions, attributes
uniform int u_nattr, u_cull, u_depth, u_sources, u_ntri;
uniform float u_unc0, u_unc1;
uniform uint u_clear_mask;  // PASS_CLEAR: bit p clears outb plane p

// --- core/fast_math.h, operation for operation ---------------------------------------------------------------
float fm_log2(float x) {
  uint bits = floatBitsToUint(x);
  int e = int((bits >> 23) & 0xffu) - 127;
  bits = (bits & 0x007fffffu) | 0x3f800000u;
  float m = uintBitsToFloat(bits);
  const bool high = m > FM_SQRT2;
  m = high ? 0.5 * m : m;
  e += high ? 1 : 0;
  const float t = (m - 1.0) / (m + 1.0);
  const float t2 = t * t;
  const float s = t * (1.0 + t2 * (FM_THIRD + t2 * (FM_FIFTH + t2 * (FM_SEVENTH + t2 * FM_NINTH))));
  return float(e) + FM_2_LN2 * s;
}
float fm_exp2(float y) {
  y = y > -126.0 ? y : -126.0;
  y = y < 127.0 ? y : 127.0;
  const int biased = int(y + 127.5);  // > 0, so truncation rounds
  const float f = (y - float(biased - 127)) * FM_LN2;
  const float p = 1.0 + f * (1.0 + f * (0.5 + f * (FM_I6 + f * (FM_I24 + f * (FM_I120 + f * (FM_I720 + f * FM_I5040))))));
  return p * uintBitsToFloat(uint(biased) << 23);
}
float fm_pow(float x, float p) {
  const bool positive = x > FM_TINY;
  const float r = fm_exp2(p * fm_log2(positive ? x : 1.0));
  return positive ? r : (p == 0.0 ? 1.0 : 0.0);
}

// didyk_options.h's smoothstep (not GLSL's: the degenerate range has its own rule).
float didyk_smoothstep(float lo, float hi, float x) {
  if (hi <= lo) return x >= hi ? 1.0 : 0.0;
  const float t = clamp((x - lo) / (hi - lo), 0.0, 1.0);
  return t * t * (3.0 - 2.0 * t);
}

// grid_warp.cpp's eye_tracking_factor (section 6).
float eye_tracking_factor(float dps) {
  if (dps <= 70.0) return 1.0;
  if (dps >= 90.0) return 0.0;
  const float t = (dps - 70.0) / 20.0;
  return 1.0 - t * t * (3.0 - 2.0 * t);
}

uint gp(uint plane) { return plane * u_nv; }  // first element of grid plane `plane`

// --- flow ----------------------------------------------------------------------------------------------------
void pass_score(ivec2 p, uint i) {
  const int W = u_size.x, H = u_size.y;
  float s = NEG_INF;
  if (p.y + 1 < H && p.x + 1 < W) {
    const uint a = i, b = i + uint(W);
    const float d1x = img[P_MX * u_n + a] - img[P_MX * u_n + b + 1u];
    const float d1y = img[P_MY * u_n + a] - img[P_MY * u_n + b + 1u];
    const float d2x = img[P_MX * u_n + a + 1u] - img[P_MX * u_n + b];
    const float d2y = img[P_MY * u_n + a + 1u] - img[P_MY * u_n + b];
    const float g = sqrt(max(d1x * d1x + d1y * d1y, d2x * d2x + d2y * d2y));
    const float vx = float(((p.x + u_half) / u_cell) * u_cell - (p.x + 1));
    const float vy = float(((p.y + u_half) / u_cell) * u_cell - (p.y + 1));
    s = g - u_bias * sqrt(vx * vx + vy * vy);
  }
  img[P_SCORE * u_n + i] = s;
}

// Level texel q of the max-pyramid: value at off + q, pixel index (as uint) at off + n + q.
void pass_max(ivec2 q) {
  if (q.x >= u_lsize.x || q.y >= u_lsize.y) return;
  const int W = u_size.x, H = u_size.y;
  float best = NEG_INF;
  int where = -1;
  if (u_first != 0) {
    for (int dy = 0; dy < 2; ++dy) {
      const int y = 2 * q.y + dy - u_offset;
      if (y < 0 || y >= H) continue;
      for (int dx = 0; dx < 2; ++dx) {
        const int x = 2 * q.x + dx - u_offset;
        if (x < 0 || x >= W) continue;
        const float v = img[P_SCORE * u_n + uint(y * W + x)];
        if (v > best || where < 0) {
          best = v;
          where = y * W + x;
        }
      }
    }
  } else {
    const uint pn = uint(u_psize.x * u_psize.y);
    for (int dy = 0; dy < 2; ++dy) {
      const int cy = 2 * q.y + dy;
      if (cy >= u_psize.y) continue;
      for (int dx = 0; dx < 2; ++dx) {
        const int cx = 2 * q.x + dx;
        if (cx >= u_psize.x) continue;
        const uint c = uint(cy * u_psize.x + cx);
        const float pv = mp[u_off_prev + c];
        const int pi = int(mp_u[u_off_prev + pn + c]);
        if (pi >= 0 && (pv > best || where < 0)) {
          best = pv;
          where = pi;
        }
      }
    }
  }
  const uint n = uint(u_lsize.x * u_lsize.y), k = uint(q.y * u_lsize.x + q.x);
  mp[u_off_cur + k] = best;
  mp_u[u_off_cur + n + k] = uint(where);
}

// GridBuilder::build's vertex loop; the lookup level's size and offset are u_lsize / u_off_cur.
void pass_vertex(ivec2 g) {
  if (g.x >= u_grid.x || g.y >= u_grid.y) return;
  const int W = u_size.x, H = u_size.y;
  const int i = g.x, j = g.y;
  const uint v = uint(j * u_grid.x + i);
  int X = min(i * u_cell, W), Y = min(j * u_cell, H);
  const bool border = i == 0 || j == 0 || i == u_grid.x - 1 || j == u_grid.y - 1;
  grid[gp(G_BORDER) + v] = border ? 1.0 : 0.0;
  grid[gp(G_SNAP) + v] = 0.0;
  if (border) {
    grid[gp(G_X) + v] = float(X);
    grid[gp(G_Y) + v] = float(Y);
    grid[gp(G_MX) + v] = 0.0;
    grid[gp(G_MY) + v] = 0.0;
    return;
  }
  if (u_snap != 0 && i < u_lsize.x && j < u_lsize.y) {  // MaxPyramid::at
    const uint n = uint(u_lsize.x * u_lsize.y), k = uint(j * u_lsize.x + i);
    const int where = int(mp_u[u_off_cur + n + k]);
    const float value = mp[u_off_cur + k];
    if (where >= 0 && value >= u_snap_threshold) {
      X = where % W + 1;
      Y = where / W + 1;
      grid[gp(G_SNAP) + v] = value;
    }
  }
  grid[gp(G_X) + v] = float(X);
  grid[gp(G_Y) + v] = float(Y);
  // The nearest surface of the (up to) four pixels around the corner.
  int best = -1;
  float best_depth = POS_INF;
  for (int dy = -1; dy <= 0; ++dy)
    for (int dx = -1; dx <= 0; ++dx) {
      const int px = clamp(X + dx, 0, W - 1), py = clamp(Y + dy, 0, H - 1);
      const int k = py * W + px;
      const float z = img[P_Z * u_n + uint(k)];
      if (best < 0 || z < best_depth) {
        best = k;
        best_depth = z;
      }
    }
  float mx = img[P_MX * u_n + uint(best)], my = img[P_MY * u_n + uint(best)];
  if (!is_finite_bits(mx) || !is_finite_bits(my)) mx = my = 0.0;
  if (u_speed_scale > 0.0) {
    const float f = eye_tracking_factor(sqrt(mx * mx + my * my) * u_speed_scale);
    mx *= f;
    my *= f;
  }
  grid[gp(G_MX) + v] = mx;
  grid[gp(G_MY) + v] = my;
}

// --- per slot: extrapolation, distortion, blur strength -------------------------------------------------------
void pass_extrapolate(ivec2 g) {
  if (g.x >= u_grid.x || g.y >= u_grid.y) return;
  const uint v = uint(g.y * u_grid.x + g.x);
  grid[gp(u_slot) + v] = grid[gp(G_X) + v] - u_t * grid[gp(G_MX) + v];
  grid[gp(u_slot + 1u) + v] = grid[gp(G_Y) + v] - u_t * grid[gp(G_MY) + v];
}

float edge_change(uint p, uint q) {
  const uint tx = gp(u_slot), ty = gp(u_slot + 1u);
  const float ex = (grid[tx + q] - grid[tx + p]) - (grid[gp(G_X) + q] - grid[gp(G_X) + p]);
  const float ey = (grid[ty + q] - grid[ty + p]) - (grid[gp(G_Y) + q] - grid[gp(G_Y) + p]);
  return sqrt(ex * ex + ey * ey);
}
double area2(uint xs, uint ys, uint p, uint q, uint r) {
  const double ax = double(grid[xs + q]) - double(grid[xs + p]), ay = double(grid[ys + q]) - double(grid[ys + p]);
  const double bx = double(grid[xs + r]) - double(grid[xs + p]), by = double(grid[ys + r]) - double(grid[ys + p]);
  return ax * by - ay * bx;
}
void pass_cell_distortion(ivec2 c) {
  const int cx = u_grid.x - 1, cy = u_grid.y - 1;
  if (c.x >= cx || c.y >= cy) return;
  const uint a = uint(c.y * u_grid.x + c.x), b = a + 1u, cc = a + uint(u_grid.x), d = cc + 1u;
  float dist = max(max(max(max(edge_change(a, b), edge_change(a, cc)), edge_change(b, d)), edge_change(cc, d)),
                   edge_change(a, d)) * u_inv_cell;
  const double s1 = area2(gp(G_X), gp(G_Y), a, b, d), s2 = area2(gp(G_X), gp(G_Y), a, d, cc);
  const double t1 = area2(gp(u_slot), gp(u_slot + 1u), a, b, d), t2 = area2(gp(u_slot), gp(u_slot + 1u), a, d, cc);
  if (s1 * t1 <= 0.0lf && abs(s1) > 1e-9lf) dist = FOLD_DISTORTION;
  if (s2 * t2 <= 0.0lf && abs(s2) > 1e-9lf) dist = FOLD_DISTORTION;
  grid[gp(u_slot + 4u) + uint(c.y * cx + c.x)] = min(dist, FOLD_DISTORTION);
}

void pass_vertex_blur(ivec2 g) {
  if (g.x >= u_grid.x || g.y >= u_grid.y) return;
  const int cx = u_grid.x - 1, cy = u_grid.y - 1;
  float m = 0.0;
  for (int dj = -1; dj <= 0; ++dj)
    for (int di = -1; di <= 0; ++di) {
      const int ci = g.x + di, cj = g.y + dj;
      if (ci < 0 || cj < 0 || ci >= cx || cj >= cy) continue;
      m = max(m, grid[gp(u_slot + 4u) + uint(cj * cx + ci)]);
    }
  const uint v = uint(g.y * u_grid.x + g.x);
  const float b = max(u_min_blur, didyk_smoothstep(u_dist_low, u_dist_high, m));
  grid[gp(u_slot + 3u) + v] = m;
  grid[gp(u_slot + 2u) + v] = b;
  // blur_sum_[v] += b[v], slot after slot from 0.
  grid[gp(G_BSUM) + v] = (u_first_slot != 0 ? 0.0 : grid[gp(G_BSUM) + v]) + b;
}

// --- blur and compensation --------------------------------------------------------------------------------------
void pass_display(uint i) {
  for (uint c = 0u; c < 3u; ++c)
    img[(P_V + c) * u_n + i] = fm_pow(clamp(img[(P_R + c) * u_n + i], 0.0, 1.0), u_inv_gamma);
}

float blur_src(uint k) { return u_from_img != 0 ? img[k] : bp[k]; }
// Horizontal [1 2 1]/4 at the even samples of every row of the previous level (q over lw x ph).
void pass_blur_h(ivec2 q) {
  if (q.x >= u_lsize.x || q.y >= u_psize.y) return;
  const int pw = u_psize.x, x = 2 * q.x;
  const uint tn = uint(u_lsize.x * u_psize.y);
  for (uint c = 0u; c < 3u; ++c) {
    const uint row = u_src_off + c * u_src_plane + uint(q.y * pw);
    const float a = blur_src(row + uint(max(x - 1, 0))), b = blur_src(row + uint(x));
    const float cc = blur_src(row + uint(min(x + 1, pw - 1)));
    bp[u_tmp_off + c * tn + uint(q.y * u_lsize.x + q.x)] = 0.25 * a + 0.5 * b + 0.25 * cc;
  }
}
// Vertical [1 2 1]/4 at the even rows (q over lw x lh).
void pass_blur_v(ivec2 q) {
  if (q.x >= u_lsize.x || q.y >= u_lsize.y) return;
  const int lw = u_lsize.x, ph = u_psize.y, y = 2 * q.y;
  const uint tn = uint(lw * ph), ln = uint(lw * u_lsize.y);
  for (uint c = 0u; c < 3u; ++c) {
    const uint t = u_tmp_off + c * tn + uint(q.x);
    const float a = bp[t + uint(max(y - 1, 0) * lw)], b = bp[t + uint(y * lw)];
    const float cc = bp[t + uint(min(y + 1, ph - 1) * lw)];
    bp[u_dst_off + c * ln + uint(q.y * lw + q.x)] = 0.25 * a + 0.5 * b + 0.25 * cc;
  }
}
// BlurPyramid::reconstruct_level at pixel p: the 4 rows of the level blended by the y weights at the 4 x taps,
// then the x weights (the C++ row buffer's order). Taps: x indices at off, x weights at off + 4W, y indices at
// off + 8W, y weights at off + 8W + 4H.
void pass_reconstruct(ivec2 p, uint i) {
  const uint W = uint(u_size.x), H = uint(u_size.y);
  const uint lw = uint(u_lsize.x), ln = uint(u_lsize.x * u_lsize.y);
  for (uint c = 0u; c < 3u; ++c) {
    float v;
    if (u_level0 != 0) {
      v = img[(P_V + c) * u_n + i];
    } else {
      const uint yi = u_taps_off + 8u * W + 4u * uint(p.y), yw = yi + 4u * H;
      const uint xi = u_taps_off + 4u * uint(p.x), xw = xi + 4u * W;
      const uint lv = u_src_off + c * ln;
      const uint r0 = lv + taps_u[yi] * lw, r1 = lv + taps_u[yi + 1u] * lw, r2 = lv + taps_u[yi + 2u] * lw,
                 r3 = lv + taps_u[yi + 3u] * lw;
      float row[4];
      for (uint k = 0u; k < 4u; ++k) {
        const uint x = taps_u[xi + k];
        row[k] = taps[yw] * bp[r0 + x] + taps[yw + 1u] * bp[r1 + x] + taps[yw + 2u] * bp[r2 + x] +
                 taps[yw + 3u] * bp[r3 + x];
      }
      v = taps[xw] * row[0] + taps[xw + 1u] * row[1] + taps[xw + 2u] * row[2] + taps[xw + 3u] * row[3];
    }
    const uint d = (P_L + c) * u_n + i;
    img[d] = (u_accumulate != 0 ? img[d] : 0.0) + u_weight * v;
  }
}

// compensate_span (didyk.cpp) per channel: B is the rasterised blur sum (outb plane 5).
void pass_compensate(uint i) {
  const float B = outb[5u * u_n + i];
  for (uint c = 0u; c < 3u; ++c) {
    const float oi = img[(P_R + c) * u_n + i], vi = img[(P_V + c) * u_n + i], li = img[(P_L + c) * u_n + i];
    const float lg = fm_pow(li, u_gamma);
    float top = oi, lo = lg;
    if (u_compensate != 0) {
      const float top_g = (1.0 + B) * oi - B * lg;  // N_eff (H + L)^g - (N_eff - 1) L^g, N_eff = 1 + B
      const float excess_low = ((1.0 + B) * oi - 1.0) / (B > 0.0 ? B : 1.0);
      float t = top_g > 1.0 ? 1.0 : top_g;
      lo = top_g > 1.0 ? excess_low : lg;
      t = B > 0.0 ? t : oi;
      lo = B > 0.0 ? lo : lg;
      const bool keep = (vi < li) || (oi < 0.0) || (oi > 1.0);
      top = keep ? oi : t;
      lo = keep ? oi : lo;
    }
    outb[c * u_n + i] = top;
    img[(P_LOW + c) * u_n + i] = lo;
  }
}

// debug.H and debug.Hprime of the rendered slot (didyk.cpp's compensate()).
void pass_debug_h(uint i) {
  float hv[3], hp[3];
  for (uint c = 0u; c < 3u; ++c) {
    const float l = img[(P_L + c) * u_n + i];
    hv[c] = img[(P_V + c) * u_n + i] - l;
    hp[c] = fm_pow(clamp(outb[c * u_n + i], 0.0, 1.0), u_inv_gamma) - l;
  }
  outb[6u * u_n + i] = LUM_R * hv[0] + LUM_G * hv[1] + LUM_B * hv[2];
  outb[7u * u_n + i] = LUM_R * hp[0] + LUM_G * hp[1] + LUM_B * hp[2];
}

// --- the rasteriser ----------------------------------------------------------------------------------------------
// The source depth as a key whose unsigned order is the float order (both zeros one key).
uint depth_key(float z) {
  if (z == 0.0) return 0x80000000u;
  const uint b = floatBitsToUint(z);
  return (b & 0x80000000u) != 0u ? ~b : (b | 0x80000000u);
}

// BandRaster::fragment for `pass`.
void fragment(int pass, int t, int x, int y, float u, float vv, float w0, float w1, float w2, float av[2][3]) {
  const uint pix = uint(y * u_size.x + x);
  const vec2 f = vec2(u - 0.5, vv - 0.5);
  uint zkey = 0u;
  if (u_depth != 0) {
    // Section 6: the depth of the source pixel containing (u, vv). A fragment must be nearer than +inf.
    const float z = img[P_Z * u_n + uint(reproject_nearest(f))];
    if (!(z < POS_INF)) return;
    zkey = depth_key(z);
  }
  const uint rank = u_depth != 0 ? uint(t) : uint(u_ntri - 1 - t);
  if (pass == PASS_R_DEPTH) {
    atomicMin(keys_u[pix], zkey);
    return;
  }
  if (pass == PASS_R_RANK) {
    if (u_depth == 0 || keys_u[pix] == zkey) atomicMin(keys_u[u_n + pix], rank);
    return;
  }
  if (keys_u[u_n + pix] != rank) return;
  const float a0 = w0 * av[0][0] + w1 * av[0][1] + w2 * av[0][2];
  outb[5u * u_n + pix] = a0;
  if (u_nattr > 1) outb[4u * u_n + pix] = w0 * av[1][0] + w1 * av[1][1] + w2 * av[1][2];
  if (u_sources == 0) return;
  const Taps b = reproject_bilinear(f);
  for (uint c = 0u; c < 3u; ++c) {
    const float sharp = REPROJECT_GATHER(img, (P_R + c) * u_n, b);
    outb[c * u_n + pix] = a0 > 0.0 ? sharp + a0 * (REPROJECT_GATHER(img, (P_LOW + c) * u_n, b) - sharp) : sharp;
  }
}

double cross2(double ax, double ay, double bx, double by) { return ax * by - ay * bx; }
bool owns(double dx, double dy) { return dy > 0.0lf || (dy == 0.0lf && dx < 0.0lf); }

// BandRaster::triangle over the whole image: triangle t (cell t / 2, split along its top-left to bottom-right
// diagonal) from the source grid to the target positions (grid planes u_tpx, u_tpy).
void scan_triangle(int pass, int t) {
  const int W = u_size.x, H = u_size.y, nx = u_grid.x;
  const int cell = t >> 1;
  const int a = (cell / (nx - 1)) * nx + (cell % (nx - 1));
  int v[3];
  if ((t & 1) == 0) {
    v[0] = a; v[1] = a + 1; v[2] = a + nx + 1;
  } else {
    v[0] = a; v[1] = a + nx + 1; v[2] = a + nx;
  }
  if (u_cull != 0) {
    bool zero = true;
    for (int k = 0; k < 3; ++k) zero = zero && grid[u_attr0 + uint(v[k])] == 0.0;
    if (zero) return;
  }
  double px[3], py[3];
  for (int k = 0; k < 3; ++k) {
    px[k] = double(grid[u_tpx + uint(v[k])]);
    py[k] = double(grid[u_tpy + uint(v[k])]);
  }
  double area = cross2(px[1] - px[0], py[1] - py[0], px[2] - px[0], py[2] - py[0]);
  if (abs(area) < 1e-12lf) return;
  if (area < 0.0lf) {  // a folded-over triangle: drawn too, its vertices reordered
    double s = px[1]; px[1] = px[2]; px[2] = s;
    s = py[1]; py[1] = py[2]; py[2] = s;
    const int sv = v[1]; v[1] = v[2]; v[2] = sv;
    area = -area;
  }
  const double inv_area = 1.0lf / area;
  const int xa = max(0, int(ceil(min(min(px[0], px[1]), px[2]) - 0.5lf)));
  const int xb = min(W - 1, int(floor(max(max(px[0], px[1]), px[2]) - 0.5lf)));
  const int ya = max(0, int(ceil(min(min(py[0], py[1]), py[2]) - 0.5lf)));
  const int yb = min(H - 1, int(floor(max(max(py[0], py[1]), py[2]) - 0.5lf)));
  if (xa > xb || ya > yb) return;
  double ex[3], ey[3];
  bool own[3];
  for (int k = 0; k < 3; ++k) {
    const int p = (k + 1) % 3, q = (k + 2) % 3;
    ex[k] = px[q] - px[p];
    ey[k] = py[q] - py[p];
    own[k] = owns(ex[k], ey[k]);
  }
  float su[3], sv[3], av[2][3];
  for (int k = 0; k < 3; ++k) {
    su[k] = grid[gp(G_X) + uint(v[k])];
    sv[k] = grid[gp(G_Y) + uint(v[k])];
    av[0][k] = grid[u_attr0 + uint(v[k])];
    av[1][k] = u_nattr > 1 ? grid[u_attr1 + uint(v[k])] : 0.0;
  }
  for (int y = ya; y <= yb; ++y) {
    const double cy = double(y) + 0.5lf, cx0 = double(xa) + 0.5lf;
    double e0[3];
    for (int k = 0; k < 3; ++k) {
      const int p = (k + 1) % 3;
      e0[k] = cross2(ex[k], ey[k], cx0 - px[p], cy - py[p]);
    }
    int xs = xa, xe = xb;
    bool empty = false;
    for (int k = 0; k < 3; ++k) {
      if (ey[k] > 0.0lf)
        xe = min(xe, xa + int(floor(e0[k] / ey[k])) + 1);
      else if (ey[k] < 0.0lf)
        xs = max(xs, xa + int(ceil(e0[k] / ey[k])) - 1);
      else if (e0[k] < 0.0lf)
        empty = true;
    }
    if (empty || xs > xe) continue;
    double e[3];
    for (int k = 0; k < 3; ++k) e[k] = e0[k] - ey[k] * double(xs - xa);
    for (int x = xs; x <= xe; ++x) {
      const bool inside = !(e[0] < 0.0lf || e[1] < 0.0lf || e[2] < 0.0lf) &&
                          !((e[0] == 0.0lf && !own[0]) || (e[1] == 0.0lf && !own[1]) || (e[2] == 0.0lf && !own[2]));
      if (inside) {
        const float w0 = float(e[0] * inv_area), w1 = float(e[1] * inv_area), w2 = 1.0 - w0 - w1;
        const float u = w0 * su[0] + w1 * su[1] + w2 * su[2];
        const float vv = w0 * sv[0] + w1 * sv[1] + w2 * sv[2];
        fragment(pass, t, x, y, u, vv, w0, w1, w2, av);
      }
      e[0] -= ey[0];
      e[1] -= ey[1];
      e[2] -= ey[2];
    }
  }
}

// BandRaster::uncovered.
void pass_uncovered(uint i) {
  if (keys_u[u_n + i] != kEmpty) return;
  outb[5u * u_n + i] = u_unc0;
  if (u_nattr > 1) outb[4u * u_n + i] = u_unc1;
  if (u_sources == 0) return;
  for (uint c = 0u; c < 3u; ++c) {
    const float s = img[(P_R + c) * u_n + i];
    outb[c * u_n + i] = s + u_unc0 * (img[(P_LOW + c) * u_n + i] - s);
  }
}

// draw_grid_lines: the right and the lower edge of vertex g (every write is 1.0: concurrent writes agree).
void grid_line(uint a, uint b) {
  const int W = u_size.x, H = u_size.y;
  const float ax = grid[u_tpx + a], ay = grid[u_tpy + a];
  const float dx = grid[u_tpx + b] - ax, dy = grid[u_tpy + b] - ay;
  const int steps = int(ceil(max(abs(dx), abs(dy)))) * 2 + 1;
  for (int s = 0; s <= steps; ++s) {
    const float f = float(s) / float(steps);
    const int x = clamp(int(floor(ax + f * dx)), 0, W - 1);
    const int y = clamp(int(floor(ay + f * dy)), 0, H - 1);
    outb[3u * u_n + uint(y * W + x)] = 1.0;
  }
}

void main() {
  const ivec2 g = ivec2(gl_GlobalInvocationID.xy);
  switch (u_pass) {
    case PASS_MAX: pass_max(g); return;
    case PASS_VERTEX: pass_vertex(g); return;
    case PASS_EXTRAPOLATE: pass_extrapolate(g); return;
    case PASS_CELL_DISTORTION: pass_cell_distortion(g); return;
    case PASS_VERTEX_BLUR: pass_vertex_blur(g); return;
    case PASS_BLUR_H: pass_blur_h(g); return;
    case PASS_BLUR_V: pass_blur_v(g); return;
    case PASS_R_DEPTH:
    case PASS_R_RANK:
    case PASS_R_WRITE:
      if (g.x < u_grid.x - 1 && g.y < u_grid.y - 1) {
        const int cell = g.y * (u_grid.x - 1) + g.x;
        scan_triangle(u_pass, 2 * cell);
        scan_triangle(u_pass, 2 * cell + 1);
      }
      return;
    case PASS_GRID_LINES:
      if (g.x < u_grid.x && g.y < u_grid.y) {
        const uint a = uint(g.y * u_grid.x + g.x);
        if (g.x + 1 < u_grid.x) grid_line(a, a + 1u);
        if (g.y + 1 < u_grid.y) grid_line(a, a + uint(u_grid.x));
      }
      return;
  }
  ivec2 p;
  uint i;
  if (!pixel_index(p, i)) return;
  switch (u_pass) {
    case PASS_SCORE: pass_score(p, i); return;
    case PASS_DISPLAY: pass_display(i); return;
    case PASS_RECONSTRUCT: pass_reconstruct(p, i); return;
    case PASS_COMPENSATE: pass_compensate(i); return;
    case PASS_DEBUG_H: pass_debug_h(i); return;
    case PASS_CLEAR:
      for (uint q = 0u; q < 8u; ++q)
        if ((u_clear_mask & (1u << q)) != 0u) outb[q * u_n + i] = 0.0;
      return;
    case PASS_KEYS_CLEAR:
      keys_u[i] = kEmpty;
      keys_u[u_n + i] = kEmpty;
      return;
    case PASS_UNCOVERED: pass_uncovered(i); return;
  }
}
)";

class DidykGpu final : public MorphMethod, public gpu::TimedKernel {
 public:
  DidykGpu(std::shared_ptr<gpu::Context> ctx, std::vector<gpu::Program> programs, const MorphOptions& options,
           const DidykOptions& didyk)
      : ctx_(std::move(ctx)), programs_(std::move(programs)), timer_(ctx_), options_(options), didyk_(didyk) {
    didyk_.grid.pixels_per_degree = options.pixels_per_degree;
    didyk_.grid.fps = options.fps;
  }

  void run(const Image& color, const Image* gbuffer, const Image*, std::vector<Image>& out,
           MorphTimings& t) override {
    timing_ = {};
    timing_.clock = timer_.clock();
    status_ = run_gpu(color, *gbuffer, out, t);
  }
  Status run_status() const override { return status_; }
  gpu::KernelTiming last_timing() const override { return timing_; }

 private:
  // Buffers for a w x h frame with n slots (kept while the size and the slot count stay).
  Status allocate(int w, int h, int n) {
    if (w == w_ && h == h_ && n == n_) return Status::ok();
    w_ = w;
    h_ = h;
    n_ = n;
    const GridOptions& gopt = didyk_.grid;
    nx_ = (w + gopt.cell - 1) / gopt.cell + 1;
    ny_ = (h + gopt.cell - 1) / gopt.cell + 1;
    mp_level_ = 0;
    while ((1 << mp_level_) < gopt.cell) ++mp_level_;
    // Max-pyramid levels 1..mp_level_ (MaxPyramid::build's sizes): values then indices.
    mp_off_.assign(std::size_t(mp_level_) + 1, 0);
    mp_w_.assign(std::size_t(mp_level_) + 1, 0);
    mp_h_.assign(std::size_t(mp_level_) + 1, 0);
    std::uint32_t total = 0;
    for (int l = 1; l <= mp_level_; ++l) {
      const int size = 1 << l, half = gopt.cell / 2;
      mp_w_[std::size_t(l)] = (w + half + size - 1) / size;
      mp_h_[std::size_t(l)] = (h + half + size - 1) / size;
      mp_off_[std::size_t(l)] = total;
      total += 2u * std::uint32_t(mp_w_[std::size_t(l)] * mp_h_[std::size_t(l)]);
    }
    // Blur pyramid levels 1..levels (BlurPyramid::build's sizes), three planes each, after one scratch region.
    blur_levels_ = std::max(1, int(std::ceil(didyk_.blur_level)));
    bp_w_.assign(std::size_t(blur_levels_) + 1, w);
    bp_h_.assign(std::size_t(blur_levels_) + 1, h);
    std::size_t scratch = 0;
    for (int l = 1; l <= blur_levels_; ++l) {
      bp_w_[std::size_t(l)] = (bp_w_[std::size_t(l) - 1] + 1) / 2;
      bp_h_[std::size_t(l)] = (bp_h_[std::size_t(l) - 1] + 1) / 2;
      scratch = std::max(scratch, 3 * std::size_t(bp_w_[std::size_t(l)]) * std::size_t(bp_h_[std::size_t(l) - 1]));
    }
    bp_off_.assign(std::size_t(blur_levels_) + 1, 0);
    std::size_t bp_total = scratch;
    for (int l = 1; l <= blur_levels_; ++l) {
      bp_off_[std::size_t(l)] = std::uint32_t(bp_total);
      bp_total += 3 * std::size_t(bp_w_[std::size_t(l)]) * std::size_t(bp_h_[std::size_t(l)]);
    }
    // The reconstruction's tap tables (blur_pyramid_taps), per level 1..levels: x indices, x weights, y indices,
    // y weights. Indices as uint, weights as float bits.
    std::vector<std::uint32_t> taps;
    taps_off_.assign(std::size_t(blur_levels_) + 1, 0);
    std::vector<int> index;
    std::vector<float> weight;
    for (int l = 1; l <= blur_levels_; ++l) {
      taps_off_[std::size_t(l)] = std::uint32_t(taps.size());
      for (const bool x_axis : {true, false}) {
        blur_pyramid_taps(x_axis ? w : h, x_axis ? bp_w_[std::size_t(l)] : bp_h_[std::size_t(l)], l, index,
                                 weight);
        for (const int i : index) taps.push_back(std::uint32_t(i));
        for (const float f : weight) taps.push_back(std::bit_cast<std::uint32_t>(f));
      }
    }
    auto make = [&](gpu::ImageBuffer& b, int bw, int bh, int planes) -> Status {
      auto created = gpu::ImageBuffer::create(ctx_, std::max(bw, 1), std::max(bh, 1), planes);
      if (!created) return created.error();
      b = std::move(*created);
      return Status::ok();
    };
    if (Status s = make(img_, w, h, kImgPlanes); !s) return s;
    if (Status s = make(out_, w, h, kOutPlanes); !s) return s;
    if (Status s = make(keys_, w, h, 2); !s) return s;
    if (Status s = make(mp_, int(std::max<std::uint32_t>(total, 1)), 1, 1); !s) return s;
    if (Status s = make(bp_, int(bp_total), 1, 1); !s) return s;
    if (Status s = make(taps_, int(taps.size()), 1, 1); !s) return s;
    if (Status s = make(grid_, nx_, ny_, kGridFixed + kSlotPlanes * (n - 1)); !s) return s;
    if (Status s = taps_.upload(0, taps.data()); !s) {
      w_ = 0;  // allocate again next time
      return s;
    }
    return Status::ok();
  }

  // The uniforms of the next dispatches, by name: the passes are separate programs, and each dispatch sets on its
  // program every uniform set so far (a name the program does not use is ignored).
  struct Uniform {
    std::string name;
    int kind = 0;  // 0 int, 1 uint, 2 float, 3 ivec2
    int i[2] = {0, 0};
    unsigned u = 0;
    float f = 0.0f;
  };
  Uniform& uniform(const char* name, int kind) {
    for (Uniform& x : uniforms_)
      if (x.name == name) return x;
    uniforms_.push_back({name, kind});
    return uniforms_.back();
  }
  void set(const char* name, int v) { uniform(name, 0).i[0] = v; }
  void set(const char* name, unsigned v) { uniform(name, 1).u = v; }
  void set(const char* name, float v) { uniform(name, 2).f = v; }
  void set_int2(const char* name, int x, int y) {
    Uniform& u = uniform(name, 3);
    u.i[0] = x;
    u.i[1] = y;
  }

  // One dispatch of `pass` over an nx x ny domain (u_size stays the image size: the shared snippets read it).
  Status go(Pass pass, int nx, int ny, double planes_moved) {
    const gpu::Program& program = programs_[std::size_t(pass)];
    if (Status s = program.use(); !s) return s;
    for (const Uniform& u : uniforms_) {
      if (u.kind == 0) program.set(u.name.c_str(), u.i[0]);
      if (u.kind == 1) program.set(u.name.c_str(), u.u);
      if (u.kind == 2) program.set(u.name.c_str(), u.f);
      if (u.kind == 3) program.set_int2(u.name.c_str(), u.i[0], u.i[1]);
    }
    program.set_int2("u_size", w_, h_);
    timing_.bytes_moved += planes_moved * 4.0;
    return program.dispatch_groups(unsigned((nx + gpu::kGroupSize - 1) / gpu::kGroupSize),
                                   unsigned((ny + gpu::kGroupSize - 1) / gpu::kGroupSize));
  }
  std::uint32_t gplane(int plane) const { return std::uint32_t(plane) * std::uint32_t(nx_ * ny_); }
  std::uint32_t slot_plane(int k) const { return std::uint32_t(kGridFixed + kSlotPlanes * (k - 1)); }

  // GridRasterizer::draw from the source grid to the target planes (tpx, tpy) with attribute planes attr0 (and
  // attr1 when nattr = 2) into outb planes 5 (and 4). With sources: the sharp frame and its low-pass blended by
  // attribute 0, with the depth test.
  Status raster(std::uint32_t tpx, std::uint32_t tpy, int nattr, std::uint32_t attr0, std::uint32_t attr1,
                bool sources, bool cull, float unc0, float unc1) {
    const double np = double(w_) * double(h_);
    set("u_tpx", tpx);
    set("u_tpy", tpy);
    set("u_nattr", nattr);
    set("u_attr0", attr0);
    set("u_attr1", attr1);
    set("u_sources", sources ? 1 : 0);
    set("u_depth", sources ? 1 : 0);
    set("u_cull", cull ? 1 : 0);
    set("u_unc0", unc0);
    set("u_unc1", unc1);
    set("u_ntri", 2 * (nx_ - 1) * (ny_ - 1));
    if (Status s = go(kKeysClear, w_, h_, 2 * np); !s) return s;
    // Key passes: the depth read at every fragment's source pixel and the keys read and written.
    if (sources)
      if (Status s = go(kRasterDepth, nx_ - 1, ny_ - 1, 2 * np); !s) return s;
    if (Status s = go(kRasterRank, nx_ - 1, ny_ - 1, (sources ? 3 : 1) * np); !s) return s;
    // The write: keys and depth read, the sources (sharp, low-pass) gathered, the colour and attributes written.
    const double write_planes = (sources ? 2 + 6 + 3 : 1) + nattr;
    if (Status s = go(kRasterWrite, nx_ - 1, ny_ - 1, write_planes * np); !s) return s;
    return go(kUncovered, w_, h_, (1 + nattr + (sources ? 9 : 0)) * np);
  }

  // Draws the grid at (tpx, tpy) into outb plane 3 (cleared first).
  Status grid_lines(std::uint32_t tpx, std::uint32_t tpy) {
    set("u_clear_mask", 1u << kGrid);
    if (Status s = go(kClear, w_, h_, 1.0 * w_ * h_); !s) return s;
    set("u_tpx", tpx);
    set("u_tpy", tpy);
    return go(kGridLines, nx_, ny_, 0.0);
  }

  Status download(Image& o, bool debug) {
    for (int c = 0; c < 3; ++c)
      if (Status s = out_.download(c, o.plane(kRGB[c])); !s) return s;
    if (debug)
      for (int p = 0; p < 5; ++p)
        if (Status s = out_.download(kGrid + p, o.plane(kMorphDebugLayers[p])); !s) return s;
    return Status::ok();
  }

  // --- flow (section 6): snapped grid and damped vertex motion.
  Status flow_pass(int w, int h, double np, double nv) {
    const GridOptions& gopt = didyk_.grid;
    if (gopt.snap) {
      set("u_bias", 1e-3f / float(gopt.cell));
      if (Status s = go(kScore, w, h, 3 * np); !s) return s;
      for (int l = 1; l <= mp_level_; ++l) {
        const auto L = std::size_t(l);
        set_int2("u_lsize", mp_w_[L], mp_h_[L]);
        set_int2("u_psize", l > 1 ? mp_w_[L - 1] : w, l > 1 ? mp_h_[L - 1] : h);
        set("u_off_prev", l > 1 ? mp_off_[L - 1] : 0u);
        set("u_off_cur", mp_off_[L]);
        set("u_first", l == 1 ? 1 : 0);
        set("u_offset", gopt.cell / 2);
        const double read = l == 1 ? np : 2.0 * mp_w_[L - 1] * mp_h_[L - 1];
        if (Status s = go(kMax, mp_w_[L], mp_h_[L], read + 2.0 * mp_w_[L] * mp_h_[L]); !s) return s;
      }
      const auto L = std::size_t(mp_level_);
      set_int2("u_lsize", mp_w_[L], mp_h_[L]);
      set("u_off_cur", mp_off_[L]);
    }
    set("u_snap", gopt.snap ? 1 : 0);
    set("u_snap_threshold", gopt.snap_threshold);
    set("u_speed_scale",
                 gopt.pixels_per_degree > 0.0f ? float(gopt.fps) / gopt.pixels_per_degree : 0.0f);
    if (Status s = go(kVertex, nx_, ny_, 6 * nv + 2 * nv); !s) return s;

    return Status::ok();
  }

  // --- morph (part 1): per slot the extrapolated vertices, distortion, blur strength; the blur sum B.
  Status slot_pass(int n, double nv) {
    const GridOptions& gopt = didyk_.grid;
    set("u_inv_cell", 1.0f / float(gopt.cell));
    set("u_min_blur", didyk_.min_blur);
    set("u_dist_low", didyk_.distortion_low);
    set("u_dist_high", didyk_.distortion_high);
    for (int k = 1; k < n; ++k) {
      set("u_slot", slot_plane(k));
      set("u_t", float(k) / float(n));
      set("u_first_slot", k == 1 ? 1 : 0);
      if (Status s = go(kExtrapolate, nx_, ny_, 6 * nv); !s) return s;
      if (Status s = go(kCellDistortion, nx_ - 1, ny_ - 1, 5 * nv); !s) return s;
      if (Status s = go(kVertexBlur, nx_, ny_, 5 * nv); !s) return s;
    }

    return Status::ok();
  }

  // --- blur (section 5.1): display values, their low-pass, the blur sum on the source grid, compensation.
  Status blur_pass(int w, int h, double np, bool debug) {
    set("u_gamma", options_.gamma);
    set("u_inv_gamma", 1.0f / options_.gamma);
    set("u_compensate", didyk_.compensate ? 1 : 0);
    if (Status s = go(kDisplay, w, h, 6 * np); !s) return s;
    for (int l = 1; l <= blur_levels_; ++l) {
      const auto L = std::size_t(l);
      const int pw = bp_w_[L - 1], ph = bp_h_[L - 1], lw = bp_w_[L], lh = bp_h_[L];
      set_int2("u_lsize", lw, lh);
      set_int2("u_psize", pw, ph);
      set("u_from_img", l == 1 ? 1 : 0);
      set("u_src_off", l == 1 ? std::uint32_t(kV) * std::uint32_t(w * h) : bp_off_[L - 1]);
      set("u_src_plane", std::uint32_t(pw * ph));
      set("u_tmp_off", 0u);
      set("u_dst_off", bp_off_[L]);
      if (Status s = go(kBlurH, lw, ph, 3.0 * (double(pw) * ph + double(lw) * ph)); !s) return s;
      if (Status s = go(kBlurV, lw, lh, 3.0 * (double(lw) * ph + double(lw) * lh)); !s) return s;
    }
    // BlurPyramid::reconstruct: a level, or the smooth-step blend of two.
    const float level = std::clamp(didyk_.blur_level, 0.0f, float(blur_levels_));
    const int l0 = static_cast<int>(std::floor(level));
    const float f = level - float(l0);
    auto reconstruct = [&](int lv, float weight, bool accumulate) -> Status {
      const auto L = std::size_t(lv);
      set("u_level0", lv == 0 ? 1 : 0);
      set_int2("u_lsize", bp_w_[L], bp_h_[L]);
      set("u_src_off", bp_off_[L]);
      set("u_taps_off", taps_off_[L]);
      set("u_weight", weight);
      set("u_accumulate", accumulate ? 1 : 0);
      return go(kReconstruct, w, h, 3.0 * (double(bp_w_[L]) * bp_h_[L] + np * (accumulate ? 2 : 1)));
    };
    if (f <= 0.0f || l0 >= blur_levels_) {
      if (Status s = reconstruct(std::min(l0, blur_levels_), 1.0f, false); !s) return s;
    } else {
      const float w1 = f * f * (3.0f - 2.0f * f);
      if (Status s = reconstruct(l0, 1.0f - w1, false); !s) return s;
      if (Status s = reconstruct(l0 + 1, w1, true); !s) return s;
    }
    // N_eff - 1 = sum_k b_k at every source pixel: the per-vertex sums drawn on the unwarped grid (outb plane 5).
    if (Status s = raster(gplane(kGX), gplane(kGY), 1, gplane(kGBSum), 0, false, true, 0.0f, 0.0f); !s) return s;
    if (Status s = go(kCompensate, w, h, 13 * np); !s) return s;
    if (debug)
      if (Status s = go(kDebugH, w, h, 11 * np); !s) return s;

    return Status::ok();
  }

  // --- morph (part 2): the sharp frame and its low-pass through the warped grid, blended by b_k; `ms` gets the
  // warp's time.
  Status warp_slots(int w, int h, int n, bool debug, std::vector<Image>& out, double& ms) {
    for (int k = 1; k < n; ++k) {
      const std::uint32_t sp = slot_plane(k);
      timer_.start();
      // Attributes: b_k (plane sp + 2) and, for debug.distortion only, the vertex distortion (sp + 3); an
      // uncovered pixel (never with a border-fixed grid) is blurred.
      if (Status s = raster(gplane(int(sp)), gplane(int(sp) + 1), debug ? 2 : 1, gplane(int(sp) + 2),
                            gplane(int(sp) + 3), true, false, 1.0f, 0.0f);
          !s)
        return s;
      ms += timer_.stop_ms();
      if (debug) {
        if (Status s = grid_lines(gplane(int(sp)), gplane(int(sp) + 1)); !s) return s;
        set("u_clear_mask", (1u << kH) | (1u << kHp));
        if (Status s = go(kClear, w, h, 0.0); !s) return s;
      }
      if (Status s = download(out[std::size_t(k)], debug); !s) return s;
    }
    return Status::ok();
  }

  Status run_gpu(const Image& color, const Image& gbuffer, std::vector<Image>& out, MorphTimings& t) {
    const int w = color.width(), h = color.height(), n = int(out.size());
    const bool debug = options_.debug_layers;
    if (Status s = allocate(w, h, n); !s) return s;
    const char* names[6] = {"R", "G", "B", "motion.X", "motion.Y", "depth.Z"};
    for (int p = 0; p < 6; ++p)
      if (Status s = img_.upload(p, p < 3 ? color : gbuffer, names[p]); !s) return s;
    if (Status s = ctx_->make_current(); !s) return s;
    img_.bind(0);
    out_.bind(1);
    keys_.bind(2);
    mp_.bind(3);
    bp_.bind(4);
    grid_.bind(5);
    taps_.bind(6);
    const GridOptions& gopt = didyk_.grid;
    const double np = double(w) * double(h), nv = double(nx_) * double(ny_);
    set("u_n", std::uint32_t(w * h));
    set_int2("u_grid", nx_, ny_);
    set("u_nv", std::uint32_t(nx_ * ny_));
    set("u_cell", gopt.cell);
    set("u_half", gopt.cell / 2);

    timer_.start();
    if (Status s = flow_pass(w, h, np, nv); !s) return s;
    t.flow_ms = timer_.stop_ms();
    timer_.start();
    if (Status s = slot_pass(n, nv); !s) return s;
    t.morph_ms = timer_.stop_ms();
    timer_.start();
    if (Status s = blur_pass(w, h, np, debug); !s) return s;
    t.blur_ms = timer_.stop_ms();
    // Slot 0: the compensated rendered frame; debug.grid (the snapped grid), debug.distortion 0, debug.blur = B.
    if (debug) {
      if (Status s = grid_lines(gplane(kGX), gplane(kGY)); !s) return s;
      set("u_clear_mask", 1u << kDist);
      if (Status s = go(kClear, w, h, 0.0); !s) return s;
    }
    if (Status s = download(out[0], debug); !s) return s;

    double ms = 0.0;
    if (Status s = warp_slots(w, h, n, debug, out, ms); !s) return s;
    t.morph_ms += ms;
    timing_.kernel_ms = t.flow_ms + t.morph_ms + t.blur_ms;
    return Status::ok();
  }

  std::shared_ptr<gpu::Context> ctx_;
  std::vector<gpu::Program> programs_;  // one per Pass
  gpu::Timer timer_;
  MorphOptions options_;
  DidykOptions didyk_;  // with the eye-tracking limit of options_
  int w_ = 0, h_ = 0, n_ = 0, nx_ = 0, ny_ = 0, mp_level_ = 0, blur_levels_ = 0;
  std::vector<int> mp_w_, mp_h_, bp_w_, bp_h_;
  std::vector<std::uint32_t> mp_off_, bp_off_, taps_off_;
  gpu::ImageBuffer img_, out_, keys_, mp_, bp_, taps_, grid_;
  std::vector<Uniform> uniforms_;
  Status status_;
  gpu::KernelTiming timing_;
};

}  // namespace

Expected<std::unique_ptr<MorphMethod>> make_didyk_method_gpu(std::shared_ptr<gpu::Context> context,
                                                             const MorphOptions& options) {
  using detail::DidykOptions;
  const DidykOptions& didyk = method_options<DidykOptions>(options.per_method, "didyk");
  if (Status s = didyk.check(); !s) return s.error();
  if (Status s = gpu::Context::ensure(context); !s) return s.error();
  // One program per pass (u_pass a constant): the compiler keeps only that pass's code. (One program switching on
  // a uniform runs every branch under a mask on llvmpipe, which cannot know the switch is uniform.)
  const std::string defines = constants();
  std::vector<gpu::Program> programs;
  for (int pass = 0; pass <= kGridLines; ++pass) {
    const std::string which = "#define u_pass " + std::to_string(pass) + "\n";
    auto program = gpu::Program::compile(
        context, "didyk pass " + std::to_string(pass),
        {gpu::glsl::prelude(), which, gpu::glsl::storage(0, "img"), gpu::glsl::storage(1, "outb"),
         gpu::glsl::storage(2, "keys"), gpu::glsl::storage(3, "mp"), gpu::glsl::storage(4, "bp"),
         gpu::glsl::storage(5, "grid"), gpu::glsl::storage(6, "taps"), defines, gpu::glsl::reproject(), kDidykMain});
    if (!program) return program.error();
    programs.push_back(std::move(*program));
  }
  return std::unique_ptr<MorphMethod>(new DidykGpu(std::move(context), std::move(programs), options, didyk));
}
}  // namespace temporal::morph
