// `drobot` (drobot.cpp, seed 002) as GLSL compute kernels, both modes, with the same arithmetic per texel and pixel
// and the same state planes (cache mode: cache.<c>, cache.depth, cache.frames, cache.id; refresh mode: history.<c>,
// prev.depth, prev.id), so that a state file written by either device resumes on the other.
//  cache mode (section 7.2): G (low resolution) the cache grid, one sample per k x k block at its centre
//    (cache_grid_row); A (low resolution) steps 3-5, Listing 7.2 on the shared GLSL reprojection in the cache grid
//    with the exponential history and its running convergence (accumulate_cache_row); F twice (low resolution)
//    step 6, Listing 7.3 horizontal then vertical (bilateral_row); U (full resolution) step 7, Listing 7.1 from
//    the block centres (drobot_upsample_row, CacheUpsample::row). (The C++ runs them as one wavefront, run_cache.)
//  refresh mode (Figure 7.12): R (full resolution) Listing 7.1 from this frame's samples, the sample itself where
//    the pixel was shaded, else the history blended by Listing 7.2's confidence (refresh_row).
// What can differ from the C++: multiply-adds contracted into FMAs differently by the driver and GCC, and for a
// --normal-power other than 32 the fast_exp2 / fast_log2 polynomials likewise; every decision (hit, a block's
// validity) is the same on the tests' sequences. Bounds: docs/gpu.md.
#include "drobot_options.h"
#include "gpu_methods.h"
#include "temporal/gpu/glsl.h"
#include "temporal/gpu/timer.h"
#include "temporal/upsample/drobot.h"

#include <cstdio>
#include <string>

namespace temporal::upsample {
namespace {

std::string constants() {
  const auto line = gpu::glsl::float_constant;  // "const float NAME = VALUE;", the float exactly
  return line("kCenterWeight", kDrobotCenterWeight) + line("kTap0", kDrobotTapWeights[0]) +
         line("kTap1", kDrobotTapWeights[1]) + line("kTap2", kDrobotTapWeights[2]) +
         line("kTap3", kDrobotTapWeights[3]) + line("kE", kDrobotE) + line("kDepthBias", kDrobotDepthBias) +
         line("kLn2", 0.69314718056f) + line("kInv3", 1.0f / 3) + line("kInv5", 1.0f / 5) + line("kInv7", 1.0f / 7) +
         line("kInv9", 1.0f / 9) + line("k2OverLn2", 2.8853900817779268f) + line("kInv6", 1.0f / 6) +
         line("kInv24", 1.0f / 24) + line("kInv120", 1.0f / 120) + line("kInv720", 1.0f / 720) +
         line("kInv5040", 1.0f / 5040) + R"(

int floor_div(int a, int b) { return (a >= 0) ? a / b : -((-a + b - 1) / b); }
float floor_vec(float x) {  // reproject::floor_vec
  const float t = float(int(x));
  return t > x ? t - 1.0 : t;
}
)" + std::string(sampling_grid_glsl());
}

// Listing 7.1 (drobot_upsample_row) for a full-resolution pixel from a coarse grid whose samples sit at
// k x + s (TapTable with offset s): geometry coarse(q, 0..3) (z, N), availability coarse_avail(q), values
// coarse_value(c, q), the bilinear table tab (4 entries per (dy, dx)). The kernel defines the three macros.
constexpr const char* kUpsample = R"(
uniform int u_gsx, u_gsy;  // the coarse grid's sample offset in the block
uniform float u_inv_range, u_power;
uniform bool u_normals, u_pow32;

float fast_log2(float x) {  // upsample_internal.h
  const uint bits = floatBitsToUint(x);
  const float e = float(int((bits >> 23) & 255u) - 127);
  const float m = uintBitsToFloat((bits & 0x7fffffu) | 0x3f800000u);
  const float t = (m - 1.0) / (m + 1.0);
  const float t2 = t * t;
  const float s = t * (1.0 + t2 * (kInv3 + t2 * (kInv5 + t2 * (kInv7 + t2 * kInv9))));
  return e + s * k2OverLn2;
}
float fast_exp2(float x) {  // upsample_internal.h
  uint u = floatBitsToUint(x);
  u &= uint(int(u) >> 31);
  u = u < 0xC2FC0000u ? u : 0xC2FC0000u;
  x = uintBitsToFloat(u);
  const float xi = floor_vec(x);
  const float f = (x - xi) * kLn2;
  const float p = 1.0 + f * (1.0 + f * (0.5 + f * (kInv6 + f * (kInv24 + f * (kInv120 + f * (kInv720 + f * kInv5040))))));
  return p * uintBitsToFloat(uint(int(xi) + 127) << 23);
}

float coarse_weight(uint q, float zi, float ax, float ay, float az) {
  const float d = ax * COARSE(q, 1) + ay * COARSE(q, 2) + az * COARSE(q, 3);
  const float dot_ = (1e-8 < d) ? d : 1e-8;  // std::max(1e-8f, d)
  float d2 = dot_ * dot_;
  d2 *= d2;
  d2 *= d2;
  d2 *= d2;
  d2 *= d2;
  const float nw = u_normals ? (u_pow32 ? d2 : fast_exp2(u_power * fast_log2(dot_))) : 1.0;
  const float w = nw / (kDepthBias + abs(zi - COARSE(q, 0)) * u_inv_range) * COARSE_AVAIL(q);
  return w >= 0.0 ? w : 0.0;
}

// Writes the C values of pixel p into outb's planes 0..C-1; returns the sum of weights (debug.confidence).
float listing71(ivec2 p, uint i) {
  const int k = u_k, lw = u_low.x, lh = u_low.y;
  const int x0 = floor_div(p.x - u_gsx, k), y0 = floor_div(p.y - u_gsy, k);
  const int dx = p.x - u_gsx - k * x0, dy = p.y - u_gsy - k * y0;
  const float cv0 = (x0 >= 0 && x0 < lw) ? 1.0 : 0.0, cv1 = (x0 + 1 >= 0 && x0 + 1 < lw) ? 1.0 : 0.0;
  const float vy0 = (y0 >= 0 && y0 < lh) ? 1.0 : 0.0, vy1 = (y0 + 1 >= 0 && y0 + 1 < lh) ? 1.0 : 0.0;
  const uint i0 = uint(clamp(x0, 0, lw - 1)), i1 = uint(clamp(x0 + 1, 0, lw - 1));
  const uint r0 = uint(clamp(y0, 0, lh - 1)) * uint(lw), r1 = uint(clamp(y0 + 1, 0, lh - 1)) * uint(lw);
  const uint te = uint(dy * k + dx) * 4u;
  const float zi = gb[i], ax = gb[u_n + i], ay = gb[2u * u_n + i], az = gb[3u * u_n + i];
  const float w00 = coarse_weight(r0 + i0, zi, ax, ay, az) * tab[te] * cv0 * vy0;
  const float w01 = coarse_weight(r0 + i1, zi, ax, ay, az) * tab[te + 1u] * cv1 * vy0;
  const float w10 = coarse_weight(r1 + i0, zi, ax, ay, az) * tab[te + 2u] * cv0 * vy1;
  const float w11 = coarse_weight(r1 + i1, zi, ax, ay, az) * tab[te + 3u] * cv1 * vy1;
  const float ws = w00 + w01 + w10 + w11;
  const float t0 = tab[te] * cv0 * vy0, t1 = tab[te + 1u] * cv1 * vy0, t2 = tab[te + 2u] * cv0 * vy1,
              t3 = tab[te + 3u] * cv1 * vy1;
  const float ts = t0 + t1 + t2 + t3;
  for (int c = 0; c < u_C; ++c) {
    const float l00 = COARSE_VALUE(c, r0 + i0), l01 = COARSE_VALUE(c, r0 + i1);
    const float l10 = COARSE_VALUE(c, r1 + i0), l11 = COARSE_VALUE(c, r1 + i1);
    const float a = w00 > 0.0 ? l00 : 0.0, b = w01 > 0.0 ? l01 : 0.0;
    const float cc = w10 > 0.0 ? l10 : 0.0, d = w11 > 0.0 ? l11 : 0.0;
    // No usable coarse sample at all: the plain bilinear value (from whatever the buffer holds).
    const float fallback = ts > 0.0 ? (t0 * l00 + t1 * l01 + t2 * l10 + t3 * l11) / ts : 0.0;
    const float fb = abs(fallback) <= 3.0e38 ? fallback : 0.0;
    outb[uint(c) * u_n + i] = ws > 0.0 ? (w00 * a + w01 * b + w10 * cc + w11 * d) / ws : fb;
  }
  return ws;
}
)";

// G: the cache grid (dispatch lw x lh). cg (5): planes 0 z, 1 prevDepth.Z, 2-4 N, 5-6 motion in cache texels, 7 id.
constexpr const char* kGridMain = R"(
void main() {
  ivec2 p;
  uint j;
  if (!pixel_index(p, j)) return;
  const int k = u_k;
  const uint i = uint(min(u_full.y - 1, k * p.y + k / 2) * u_full.x + min(u_full.x - 1, k * p.x + k / 2));
  const float inv_k = 1.0 / float(k);
  cg[j] = gb[i];
  cg[u_ln + j] = gb[6u * u_n + i];
  cg[2u * u_ln + j] = gb[u_n + i];
  cg[3u * u_ln + j] = gb[2u * u_n + i];
  cg[4u * u_ln + j] = gb[3u * u_n + i];
  cg[5u * u_ln + j] = gb[4u * u_n + i] * inv_k;
  cg[6u * u_ln + j] = gb[5u * u_n + i] * inv_k;
  cg_u[7u * u_ln + j] = gb_u[7u * u_n + i];
}
)";

// A: steps 3-5 (dispatch lw x lh, u_size = the cache grid, so the reprojection works in it). cache (6): per parity
// p at (C + 3) p: C value planes, depth, frame count, id; cb (7): C planes of CB, then hit, w, conf, strength.
constexpr const char* kAccumulateDecl = R"(
uniform bool u_history, u_use_ids, u_warped, u_point;
uniform float u_tol, u_warped_tol, u_threshold, u_convergence_time, u_nmax;
uniform uint u_cur, u_prv;  // plane bases of the parities in `cache`
#define REPROJECT_PREV_Z(q) cache[u_prv + uint(u_C + 0) * u_ln + uint(q)]
#define REPROJECT_PREV_ID(q) cache_u[u_prv + uint(u_C + 2) * u_ln + uint(q)]
)";

constexpr const char* kAccumulateMain = R"(
void main() {
  ivec2 p;
  uint j;
  const bool inside = pixel_index(p, j);
  count_begin();
  if (inside) {
    const int C = u_C, k = u_k;
    const uint zb = uint(C) * u_ln, nb = uint(C + 1) * u_ln, ib = uint(C + 2) * u_ln;
    const float z = cg[j];
    bool hit = false;
    float nc = 0.0, zc = 0.0;
    float vals[16];
    if (u_history) {
      const float mx = cg[5u * u_ln + j], my = cg[6u * u_ln + j];
      Taps t = reproject_taps(p, vec2(mx, my));
      const float ze = expect_depth(z, cg[u_ln + j], u_warped);
      hit = reproject_test(t, ze, cg_u[7u * u_ln + j], true, u_use_ids, expect_tolerance(u_tol, u_warped_tol, u_warped));
      if (u_point) {  // Figure 7.5's point filtering: the surviving tap with the largest weight
        int best = 0;
        for (int q = 1; q < 4; ++q) best = t.w[q] > t.w[best] ? q : best;
        const uint qb = uint(t.q[best]);
        nc = cache[u_prv + nb + qb];
        for (int c = 0; c < C; ++c) vals[c] = cache[u_prv + uint(c) * u_ln + qb];
      } else {
        nc = REPROJECT_GATHER(cache, u_prv + nb, t);
        for (int c = 0; c < C; ++c) vals[c] = REPROJECT_GATHER(cache, u_prv + uint(c) * u_ln, t);
      }
      // listing72_depth_row: the bilinear previous depth over all four taps.
      const float u = float(p.x) + mx, v = float(p.y) + my;
      const float tx = u - floor_vec(u), ty = v - floor_vec(v);
      const uint pz = u_prv + zb;
      zc = (1.0 - tx) * (1.0 - ty) * cache[pz + uint(t.q[0])] + tx * (1.0 - ty) * cache[pz + uint(t.q[1])] +
           (1.0 - tx) * ty * cache[pz + uint(t.q[2])] + tx * ty * cache[pz + uint(t.q[3])];
    }
    // cache_confidence / drobot_cache_confidence
    float conf = 0.0;
    if (hit) {
      const float dz = z > 0.0 ? (z - zc) / z : 1.0;
      conf = 1.0 - clamp((abs(dz) - u_threshold) * u_convergence_time, 0.0, 1.0);
    }
    const float n_prev = conf > 0.0 ? nc : 0.0;
    // drobot_convergence_weight
    const float np = n_prev * conf, cap = u_nmax - 1.0;
    const float nm = cap < np ? cap : np;
    const float n_new = nm + 1.0;
    const float w = nm / (nm + 1.0);
    const float zs = gb[uint(k * p.y + u_sy) * uint(u_full.x) + uint(k * p.x + u_sx)];
    const bool finite = low_valid(j);
    const bool valid = finite && z > 0.0 && abs(zs - z) <= u_threshold * z;
    const float n = valid ? n_new : n_prev * conf;
    for (int c = 0; c < C; ++c) {
      const float hist = conf > 0.0 ? vals[c] : 0.0;
      const float r = lowb[uint(c) * u_ln + j];
      float value = valid ? hist * w + r * (1.0 - w) : hist;  // exponential_history
      if (n <= 0.0) value = finite ? r : 0.0;  // nothing of this surface yet (the filter fills it)
      cb[uint(c) * u_ln + j] = value;
    }
    cache[u_cur + nb + j] = n;
    cache[u_cur + zb + j] = z;
    cache_u[u_cur + ib + j] = cg_u[7u * u_ln + j];
    const float convergence = min(1.0, n / u_nmax);
    cb[uint(C) * u_ln + j] = conf;
    cb[uint(C + 1) * u_ln + j] = n > 0.0 ? 1.0 : 0.0;
    cb[uint(C + 2) * u_ln + j] = convergence;
    cb[uint(C + 3) * u_ln + j] = 1.0 - convergence;
    count_add(0, conf > 0.0);
  }
  count_end();
}
)";

// F: one direction of Listing 7.3 (dispatch lw x lh): values (fsrc, 8) at u_src_base + c with availability
// u_avail_in, into fdst (9) at u_dst_base + c and availability u_avail_out; this frame's cache depth (cache, 6) and
// the strength (cb, 7).
constexpr const char* kFilterMain = R"(
uniform bool u_horizontal;
uniform float u_amp;
uniform uint u_src_base, u_dst_base, u_avail_in, u_avail_out, u_z_base, u_strength_base;

// The texel at offset o along the pass's direction, edges repeated.
uint tap(ivec2 p, int o) {
  const int w = u_size.x, h = u_size.y;
  const int xx = u_horizontal ? clamp(p.x + o, 0, w - 1) : p.x;
  const int yy = u_horizontal ? p.y : clamp(p.y + o, 0, h - 1);
  return uint(yy * w + xx);
}

void main() {
  ivec2 p;
  uint i;
  if (!pixel_index(p, i)) return;
  const float zc = cache[u_z_base + i];
  const float inv_z = zc > 0.0 ? 1.0 / zc : 0.0;
  const float av = fsrc[u_avail_in + i];
  const float s_i = av > 0.0 ? cb[u_strength_base + i] : 1.0;
  const int pairs[8] = int[8](-3, -4, -1, -2, 1, 2, 3, 4);
  const float tapw[4] = float[4](kTap0, kTap1, kTap2, kTap3);
  float wsum_all = 0.0;
  for (int c = 0; c < u_C; ++c) {
    const uint sb = u_src_base + uint(c) * u_ln;
    float sum = kCenterWeight * av * fsrc[sb + i], wsum = kCenterWeight * av;
    for (int t = 0; t < 4; ++t) {
      const uint q0 = tap(p, pairs[2 * t]), q1 = tap(p, pairs[2 * t + 1]);
      const float a0 = fsrc[u_avail_in + q0], a1 = fsrc[u_avail_in + q1];
      if (a0 + a1 <= 0.0) continue;
      const float v = (a0 * fsrc[sb + q0] + a1 * fsrc[sb + q1]) / (a0 + a1);
      const float zt = (a0 * cache[u_z_base + q0] + a1 * cache[u_z_base + q1]) / (a0 + a1);
      // drobot_filter_tap_weight
      const float wt = 0.5 * (a0 + a1) * s_i * (tapw[t] / (kE + u_amp * abs(zc * inv_z - zt * inv_z)));
      sum += wt * v;
      wsum += wt;
    }
    fdst[u_dst_base + uint(c) * u_ln + i] = wsum > 0.0 ? sum / wsum : fsrc[sb + i];
    wsum_all = wsum;
  }
  fdst[u_avail_out + i] = wsum_all > 0.0 ? 1.0 : 0.0;
}
)";

// U: step 7 (dispatch W x H): Listing 7.1 from the filtered cache (cache planes u_val_base + c, availability
// u_avail), the cache grid's geometry (cg), the debug planes per block.
constexpr const char* kCacheUpsampleDecl = R"(
uniform uint u_val_base, u_avail, u_hit_base, u_conv_base, u_frames_base;
uniform bool u_debug;
#define COARSE(q, plane) cg[(plane == 0 ? 0u : uint(plane + 1)) * u_ln + (q)]
#define COARSE_AVAIL(q) cache[u_avail + (q)]
#define COARSE_VALUE(c, q) cache[u_val_base + uint(c) * u_ln + (q)]
)";
constexpr const char* kCacheUpsampleMain = R"(
void main() {
  ivec2 p;
  uint i;
  if (!pixel_index(p, i)) return;
  const float ws = listing71(p, i);
  if (u_debug) {
    const int k = u_k;
    const uint j = uint(clamp(p.y / k, 0, u_low.y - 1) * u_low.x + clamp(p.x / k, 0, u_low.x - 1));
    const uint d = uint(u_C) * u_n + i;
    outb[d] = ws;                                        // debug.confidence
    outb[d + u_n] = cb[u_hit_base + j] > 0.0 ? 0.0 : 1.0;  // debug.disocclusion
    outb[d + 2u * u_n] = cb[u_conv_base + j];            // debug.convergence
    outb[d + 3u * u_n] = cache[u_frames_base + j];       // debug.historyWeight
  }
}
)";

// R: refresh mode (dispatch W x H): Listing 7.1 from this frame's samples, then refresh_row's choice.
constexpr const char* kRefreshDecl = R"(
uniform bool u_history, u_use_ids, u_warped, u_debug;
uniform float u_tol, u_warped_tol, u_threshold, u_convergence_time;
// The sample's pixel (k x + sx, k y + sy) in the full-resolution G-buffer (gather_low_geometry).
#define SAMPLE_PIXEL(q) \
  ((uint(u_k) * ((q) / uint(u_low.x)) + uint(u_sy)) * uint(u_full.x) + uint(u_sx) + uint(u_k) * ((q) % uint(u_low.x)))
#define COARSE(q, plane) gb[uint(plane) * u_n + SAMPLE_PIXEL(q)]
#define COARSE_AVAIL(q) (low_valid(q) ? 1.0 : 0.0)
// A tap that is no sample holds 0 for listing71's fallback (run_refresh's refresh_low).
#define COARSE_VALUE(c, q) (low_valid(q) ? lowb[uint(c) * u_ln + (q)] : 0.0)
#define REPROJECT_PREV_Z(q) prevg[uint(q)]
#define REPROJECT_PREV_ID(q) prevg_u[u_n + uint(q)]
)";
constexpr const char* kRefreshMain = R"(
void main() {
  ivec2 p;
  uint i;
  const bool inside = pixel_index(p, i);
  count_begin();
  if (inside) {
    const float ws = listing71(p, i);
    const int k = u_k, C = u_C;
    const int x0 = floor_div(p.x - u_sx, k), y0 = floor_div(p.y - u_sy, k);
    const bool computed = p.x - u_sx - k * x0 == 0 && p.y - u_sy - k * y0 == 0;
    const uint q = uint(clamp(y0, 0, u_low.y - 1) * u_low.x + clamp(x0, 0, u_low.x - 1));
    float conf = 1.0;
    if (computed && low_valid(q)) {
      for (int c = 0; c < C; ++c) outb[uint(c) * u_n + i] = lowb[uint(c) * u_ln + q];
    } else {
      bool hit = false;
      float zc = 0.0;
      Taps t;
      const float mx = gb[4u * u_n + i], my = gb[5u * u_n + i];
      if (u_history) {
        t = reproject_taps(p, vec2(mx, my));
        const float ze = expect_depth(gb[i], gb[6u * u_n + i], u_warped);
        hit = reproject_test(t, ze, gb_u[7u * u_n + i], true, u_use_ids, expect_tolerance(u_tol, u_warped_tol, u_warped));
        const float u = float(p.x) + mx, v = float(p.y) + my;
        const float tx = u - floor_vec(u), ty = v - floor_vec(v);
        zc = (1.0 - tx) * (1.0 - ty) * prevg[uint(t.q[0])] + tx * (1.0 - ty) * prevg[uint(t.q[1])] +
             (1.0 - tx) * ty * prevg[uint(t.q[2])] + tx * ty * prevg[uint(t.q[3])];
      }
      conf = 0.0;
      if (hit) {
        const float z = gb[i];
        const float dz = z > 0.0 ? (z - zc) / z : 1.0;
        conf = 1.0 - clamp((abs(dz) - u_threshold) * u_convergence_time, 0.0, 1.0);
      }
      if (conf > 0.0)
        for (int c = 0; c < C; ++c) {
          const uint o = uint(c) * u_n + i;
          const float fetched = REPROJECT_GATHER(hist, uint(c) * u_n, t);
          outb[o] += (fetched - outb[o]) * conf;
        }
      count_add(0, conf > 0.0);  // history
      count_add(1, conf <= 0.0);  // hole
    }
    if (u_debug) {
      const uint d = uint(C) * u_n + i;
      outb[d] = ws;                            // debug.confidence
      outb[d + u_n] = conf > 0.0 ? 0.0 : 1.0;  // debug.disocclusion
      outb[d + 2u * u_n] = conf;               // debug.convergence
    }
  }
  count_end();
}
)";

class DrobotStateGpu final : public GpuHistoryState {
 public:
  DrobotStateGpu(std::shared_ptr<gpu::Context> ctx, std::vector<gpu::Program> programs, gpu::ImageBuffer counters,
                 const Geometry& g, bool refresh)
      : GpuHistoryState(std::move(ctx), std::move(counters), g), prog_(std::move(programs)), refresh_(refresh) {}

  // DrobotState::save's planes.
  void save(Image& state) const override {
    if (out_[0].empty()) return;  // save() cannot report an error; load() names a missing plane
    const int C = int(g_.channels.size());
    if (refresh_) {
      save_history(state);
      save_previous_geometry(prevg_, has_prev_id_, g_, state);
      return;
    }
    std::vector<float> plane(std::size_t(g_.lw) * g_.lh);
    const int b = (C + 3) * cur_;
    for (int c = 0; c < C; ++c)
      if (filtered_value_download(c, plane.data()))
        put_plane(state, "cache." + g_.channels[std::size_t(c)], plane.data(), g_.lw, g_.lh);
    save_plane(cache_, b + C, state, "cache.depth");
    save_plane(cache_, b + C + 1, state, "cache.frames");
    if (has_cache_id_) {
      std::vector<std::uint32_t> ids(plane.size());
      if (cache_.download(b + C + 2, ids.data())) put_uint_plane(state, "cache.id", ids.data(), g_.lw, g_.lh);
    }
  }

  Status load(const Image& state) override {
    if (Status s = allocate(); !s) return s;
    cur_ = 1 - cur_;  // OutputPair::next()
    const int C = int(g_.channels.size());
    if (refresh_) {
      if (Status s = load_history(state); !s) return s;
      if (Status s = upload_previous_geometry(state, g_, prevg_, has_prev_id_); !s) return s;
      has_history_ = true;
      return Status::ok();
    }
    const int b = (C + 3) * cur_;
    for (int c = 0; c < C; ++c)
      if (Status s = load_plane(state, "cache." + g_.channels[std::size_t(c)], cache_, b + c, StateValues::Finite); !s)
        return s;
    if (Status s = load_plane(state, "cache.depth", cache_, b + C); !s) return s;
    if (Status s = load_plane(state, "cache.frames", cache_, b + C + 1, StateValues::Finite); !s) return s;
    // DrobotState::load clears the ids when the state has none; the next run() zero-fills them (its resize).
    std::vector<std::uint32_t> ids(std::size_t(g_.lw) * g_.lh, 0u);
    has_cache_id_ = state.uint_plane("cache.id") != nullptr;
    if (has_cache_id_)
      if (Status s = get_uint_plane(state, "cache.id", ids.data(), g_.lw, g_.lh); !s) return s;
    if (Status s = cache_.upload(b + C + 2, ids.data()); !s) return s;
    has_history_ = true;
    return Status::ok();
  }

 private:
  enum { kGrid, kAccumulate, kFilter, kCacheUpsample, kRefresh };

  // The cache's values live in the cache buffer's planes (C + 3) p + c after the vertical filter pass.
  bool filtered_value_download(int c, float* dst) const {
    return bool(cache_.download((int(g_.channels.size()) + 3) * cur_ + c, dst));
  }

  Status allocate() {
    if (!out_[0].empty()) return Status::ok();
    const int C = int(g_.channels.size()), W = g_.W, H = g_.H, lw = g_.lw, lh = g_.lh;
    if (refresh_)
      return gpu::ImageBuffer::create_all_cleared(
          ctx_, {{&out_[0], W, H, C + 4}, {&out_[1], W, H, C + 4}, {&prevg_, W, H, 2}});
    return gpu::ImageBuffer::create_all_cleared(
        ctx_, {{&out_[0], W, H, C + 4},
               {&out_[1], W, H, C + 4},
               {&cg_, lw, lh, 8},
               // Per parity C values, depth, frame count, id; then the filtered availability of this frame.
               {&cache_, lw, lh, 2 * (C + 3) + 1},
               {&cb_, lw, lh, C + 4},
               {&tmp_, lw, lh, C + 1}});
  }

  Status upload_table(const std::vector<float>& table) {
    if (tab_.empty() || tab_.width() != int(table.size())) {
      auto created = gpu::ImageBuffer::create(ctx_, int(table.size()), 1, 1);
      if (!created) return created.error();
      tab_ = std::move(*created);
    }
    return tab_.upload(0, table.data());
  }

  void set_listing71(const gpu::Program& prog, const FrameContext& f, const DrobotOptions& o, int gsx, int gsy) const {
    prog.set("u_gsx", gsx);
    prog.set("u_gsy", gsy);
    prog.set("u_inv_range", 1.0f / f.depth_range);
    prog.set("u_power", o.normal_power);
    prog.set("u_normals", int(!o.depth_only));
    prog.set("u_pow32", int(o.normal_power == 32.0f));
  }

  Status run_gpu(const FrameContext& f, bool history, FrameStats& stats) override {
    return refresh_ ? run_refresh(f, history, stats) : run_cache(f, history, stats);
  }

  Status run_cache(const FrameContext& f, bool have_history, FrameStats& stats) {
    const DrobotOptions& o = drobot_options(*f.options);
    if (f.C > 16)
      return Error::usage("drobot on the GPU takes at most 16 payload channels, not " + std::to_string(f.C));
    if (Status s = allocate(); !s) return s;
    if (Status s = frame_.upload(ctx_, f, true); !s) return s;
    if (Status s = counters_.clear(0, 1); !s) return s;
    const int k = f.grid.k, C = f.C;
    // prepare_cache_grid's table of the block centres.
    const float off = (k % 2 == 0) ? 0.5f : 0.0f;
    std::vector<float> table(std::size_t(k) * k * 4);
    for (int dy = 0; dy < k; ++dy)
      for (int dx = 0; dx < k; ++dx) {
        const float fx = (float(dx) + off) / float(k), fy = (float(dy) + off) / float(k);
        float* e = &table[std::size_t(dy * k + dx) * 4];
        e[0] = (1 - fx) * (1 - fy);
        e[1] = fx * (1 - fy);
        e[2] = (1 - fx) * fy;
        e[3] = fx * fy;
      }
    if (Status s = upload_table(table); !s) return s;
    cur_ = 1 - cur_;  // OutputPair::next()
    const int prv = 1 - cur_;
    // run_cache: its cache planes are sized before it asks, so the Upsampler's flag alone decides.
    const bool history = have_history;
    const reproject::SurfaceTest test = f.options->surface_test();
    const std::uint32_t ln = std::uint32_t(std::size_t(f.lw) * f.lh);
    const std::uint32_t cur_base = std::uint32_t((C + 3) * cur_) * ln, prv_base = std::uint32_t((C + 3) * prv) * ln;
    const std::uint32_t avail = std::uint32_t(2 * (C + 3)) * ln;  // the filtered availability (cb_avail)
    frame_.bind();
    out_[cur_].bind(2);
    cg_.bind(5);
    cache_.bind(6);
    cb_.bind(7);
    tab_.bind(10);
    counters_.bind(15);
    timer_.start();
    const gpu::Program& g = prog_[kGrid];
    if (Status s = g.use(); !s) return s;
    set_sampling_grid_uniforms(g, f);
    if (Status s = g.dispatch(f.lw, f.lh); !s) return s;
    // Steps 3-5.
    const gpu::Program& a = prog_[kAccumulate];
    if (Status s = a.use(); !s) return s;
    set_sampling_grid_uniforms(a, f);
    a.set("u_history", int(history));
    a.set("u_use_ids", int(test.use_ids && f.id != nullptr));
    a.set("u_warped", int(f.prev_z != nullptr));
    a.set("u_point", int(o.cache_point));
    a.set("u_tol", test.depth_tolerance);
    a.set("u_warped_tol", f.options->warped_depth_tolerance);
    a.set("u_threshold", o.miss_threshold);
    a.set("u_convergence_time", o.convergence_time);
    a.set("u_nmax", o.max_frames > 0 ? o.max_frames : float(k * k));
    a.set("u_cur", cur_base);
    a.set("u_prv", prv_base);
    if (Status s = a.dispatch(f.lw, f.lh); !s) return s;
    // Step 6: horizontal (CB -> tmp), then vertical (tmp -> this frame's cache values, the new HB; step 8).
    const gpu::Program& fp = prog_[kFilter];
    if (Status s = fp.use(); !s) return s;
    set_sampling_grid_uniforms(fp, f);
    fp.set("u_amp", o.filter_amp);
    fp.set("u_z_base", cur_base + std::uint32_t(C) * ln);
    fp.set("u_strength_base", std::uint32_t(C + 3) * ln);
    cb_.bind(8);
    tmp_.bind(9);
    fp.set("u_horizontal", 1);
    fp.set("u_src_base", 0u);
    fp.set("u_avail_in", std::uint32_t(C + 1) * ln);  // CB's w: the blocks with a sample of their surface
    fp.set("u_dst_base", 0u);
    fp.set("u_avail_out", std::uint32_t(C) * ln);
    if (Status s = fp.dispatch(f.lw, f.lh); !s) return s;
    tmp_.bind(8);
    cache_.bind(9);
    fp.set("u_horizontal", 0);
    fp.set("u_src_base", 0u);
    fp.set("u_avail_in", std::uint32_t(C) * ln);
    fp.set("u_dst_base", cur_base);
    fp.set("u_avail_out", avail);
    if (Status s = fp.dispatch(f.lw, f.lh); !s) return s;
    // Step 7.
    const gpu::Program& u = prog_[kCacheUpsample];
    if (Status s = u.use(); !s) return s;
    set_sampling_grid_uniforms(u, f);
    set_listing71(u, f, o, k / 2, k / 2);
    u.set("u_val_base", cur_base);
    u.set("u_avail", avail);
    u.set("u_hit_base", std::uint32_t(C) * ln);
    u.set("u_conv_base", std::uint32_t(C + 2) * ln);
    u.set("u_frames_base", cur_base + std::uint32_t(C + 1) * ln);
    u.set("u_debug", int(f.debug));
    if (Status s = u.dispatch(f.W, f.H); !s) return s;
    timing_.kernel_ms = timer_.stop_ms();
    timing_.clock = timer_.clock();
    const double full = double(f.W) * f.H * 4.0, low = double(ln) * 4.0;
    // drobot.cpp's streamed_bytes (cache mode; the motion and ids at the blocks in 32-byte sectors) plus CB and the
    // filter's passes (low resolution).
    timing_.bytes_moved = 4 * full + C * low + C * full + 3.0 * double(cache_grid_read_bytes(f.W, f.H, k, 32)) +
                          2 * (C + 3) * low + 4 * (C + 4) * low + (f.debug ? 4.0 * full : 0.0);
    static const char* const kNames[4] = {"debug.confidence", "debug.disocclusion", "debug.convergence",
                                          "debug.historyWeight"};
    if (Status s = download_result(f, kNames); !s) return s;
    has_history_ = true;
    has_cache_id_ = f.id != nullptr;
    std::uint32_t counts[4] = {};
    if (Status s = counters_.download(0, counts); !s) return s;
    stats.history_pixels = std::size_t(counts[0]) * k * k;
    stats.hole_pixels = (std::size_t(ln) - counts[0]) * std::size_t(k) * k;
    return Status::ok();
  }

  Status run_refresh(const FrameContext& f, bool have_history, FrameStats& stats) {
    const DrobotOptions& o = drobot_options(*f.options);
    if (Status s = allocate(); !s) return s;
    if (Status s = frame_.upload(ctx_, f, true); !s) return s;
    if (Status s = counters_.clear(0, 1); !s) return s;
    if (Status s = upload_table(drobot_bilinear_table(f.grid.k)); !s) return s;
    cur_ = 1 - cur_;
    const bool history = have_history && has_history_;
    const reproject::SurfaceTest test = f.options->surface_test();
    bind_history_buffers();
    tab_.bind(10);
    counters_.bind(15);
    timer_.start();
    const gpu::Program& r = prog_[kRefresh];
    if (Status s = r.use(); !s) return s;
    set_sampling_grid_uniforms(r, f);
    set_listing71(r, f, o, f.grid.sx, f.grid.sy);
    r.set("u_history", int(history));
    r.set("u_use_ids", int(test.use_ids && f.id != nullptr && has_prev_id_));
    r.set("u_warped", int(f.prev_z != nullptr));
    r.set("u_debug", int(f.debug));
    r.set("u_tol", test.depth_tolerance);
    r.set("u_warped_tol", f.options->warped_depth_tolerance);
    r.set("u_threshold", o.miss_threshold);
    r.set("u_convergence_time", o.convergence_time);
    if (Status s = r.dispatch(f.W, f.H); !s) return s;
    timing_.kernel_ms = timer_.stop_ms();
    timing_.clock = timer_.clock();
    const double full = double(f.W) * f.H * 4.0, low = double(f.lw) * f.lh * 4.0;
    timing_.bytes_moved = 4 * full + f.C * low + f.C * full + 2 * full + full + 2 * (2 * full) + f.C * full +
                          (f.debug ? 3.0 * full : 0.0);  // drobot.cpp's streamed_bytes (refresh mode)
    static const char* const kNames[3] = {"debug.confidence", "debug.disocclusion", "debug.convergence"};
    if (Status s = download_result(f, kNames); !s) return s;
    if (Status s = store_previous_geometry(f); !s) return s;
    has_history_ = true;
    std::uint32_t counts[4] = {};
    if (Status s = counters_.download(0, counts); !s) return s;
    stats.history_pixels = counts[0];
    stats.hole_pixels = counts[1];
    return Status::ok();
  }

  std::vector<gpu::Program> prog_;
  bool refresh_;
  gpu::ImageBuffer cg_, cache_, cb_, tmp_, tab_;
  bool has_cache_id_ = false, has_history_ = false;
};

}  // namespace

Expected<std::unique_ptr<MethodState>> make_drobot_state_gpu(std::shared_ptr<gpu::Context> context,
                                                             const Options& options, const Geometry& geometry) {
  if (Status s = gpu::Context::ensure(context); !s) return s.error();
  const auto floats = gpu::glsl::float_storage;  // a float-only storage block
  const std::string consts = constants();
  const std::string gb = gpu::glsl::storage(0, "gb"), lowb = floats(1, "lowb"), outb = floats(2, "outb"),
                    hist = floats(3, "hist"), prevg = gpu::glsl::storage(4, "prevg"), cg = gpu::glsl::storage(5, "cg"),
                    cache = gpu::glsl::storage(6, "cache"), cb = floats(7, "cb"), fsrc = floats(8, "fsrc"),
                    fdst = floats(9, "fdst"), tab = floats(10, "tab");
  const std::string_view pre = gpu::glsl::prelude();
  const std::vector<std::vector<std::string_view>> sources = {
      {pre, gb, lowb, cg, consts, kGridMain},
      {pre, gb, lowb, cg, cache, cb, consts, kAccumulateDecl, gpu::glsl::reproject(), kAccumulateMain},
      {pre, gb, lowb, cache, cb, fsrc, fdst, consts, kFilterMain},
      {pre, gb, lowb, outb, cg, cache, cb, tab, consts, kCacheUpsampleDecl, kUpsample, kCacheUpsampleMain},
      {pre, gb, lowb, outb, hist, prevg, tab, consts, kRefreshDecl, kUpsample, gpu::glsl::reproject(), kRefreshMain}};
  const char* names[5] = {"drobot cache grid", "drobot accumulate", "drobot filter", "drobot upsample",
                          "drobot refresh"};
  std::vector<gpu::Program> programs;
  for (std::size_t i = 0; i < sources.size(); ++i) {
    auto p = gpu::Program::compile(context, names[i], sources[i]);
    if (!p) return p.error();
    programs.push_back(std::move(*p));
  }
  auto counters = gpu::ImageBuffer::create(context, 4, 1, 1);
  if (!counters) return counters.error();
  return std::unique_ptr<MethodState>(new DrobotStateGpu(std::move(context), std::move(programs),
                                                         std::move(*counters), geometry,
                                                         drobot_options(options).refresh()));
}

}  // namespace temporal::upsample
