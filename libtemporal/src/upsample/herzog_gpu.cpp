// `herzog` (herzog.cpp, seed 000 sections 3.3-3.5) as GLSL compute kernels: the three passes of the C++ file
// comment, each a dispatch, with the same arithmetic per pixel and the same state planes (history.<c>,
// history.weight, gradient.t1..t3, gradient.wf, prev.depth, prev.id), so that a state file written by either
// device resumes on the other.
//  A (full resolution): the kernel fall-off from the previous w_f at the motion-compensated cell, h~ and w~ of
//    eq. 6 with the adaptive image kernel and w~' with the sharp one (the same host-computed tables as
//    build_kernel_tables, and the same kernel_exp2), the history fetch h_r, h_w through the shared GLSL reprojection,
//    the relative gradient of the luminance (section 3.5.1; the maximum where disoccluded, Figure 6).
//  B (gradient grid): the average of A's gradients per cell, the temporal filter |(0.4, 0.3, 0.2, 0.1) . g| with
//    the three previous gradients fetched at the cell centre's motion (written `precise`: herzog.cpp compiles it
//    with fp-contract=off), then the box pyramid (one dispatch per level) and its trilinear sample at the mip
//    level with the C++'s explicit fma()s, and eq. 8.
//  C (full resolution): eq. 7 and the bounded history-weight update, and the debug planes.
// herzog.cpp runs the same passes row by row in one sweep (its schedule only changes the order rows are computed
// in); here each pass is a dispatch over the whole image, the results between them in scratch planes.
// What can differ from the C++: where the driver and GCC (-march=native) contract a * b + c into an FMA
// differently (the weights, the Horner polynomial of kernel_exp2, eq. 7's sums), a few float ulps of a weight; every
// decision (history hit, the cell a motion vector lands in) is the same. Bounds: docs/gpu.md.
#include "gpu_methods.h"
#include "herzog.h"
#include "temporal/gpu/glsl.h"
#include "temporal/gpu/timer.h"
#include "temporal/upsample/history.h"
#include "temporal/upsample/joint_bilateral.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <string>

namespace temporal::upsample {
namespace {

// The constants of herzog.cpp and of the kernel power's polynomial (kKernelExp2), printed exactly (%.9g
// round-trips a float).
std::string constants() {
  const auto line = gpu::glsl::float_constant;  // "const float NAME = VALUE;", the float exactly
  return line("kMaxGradient", kMaxGradient) + line("kG0", kGradientWeights[0]) + line("kG1", kGradientWeights[1]) +
         line("kG2", kGradientWeights[2]) + line("kG3", kGradientWeights[3]) + line("kQ0", kKernelExp2[0]) +
         line("kQ1", kKernelExp2[1]) + line("kQ2", kKernelExp2[2]) + line("kQ3", kKernelExp2[3]) +
         line("kQ4", kKernelExp2[4]);
}

// Buffers of pass A: gb (0) and lowb (1) as GpuFrame; outb (2) this frame's output (C planes of h~, then eq. 7's h
// after pass C, then the 6 debug planes); hist (3) the previous output h_r; prevg (4) the previous depth (plane 0)
// and ids (1); scr (5) the scratch planes below; hwb (6) h_w of both parities; grid (7) the gradient grid's planes;
// tab (8) the kernel tables (log2 base, sharp kernel, hat: 4 k^2 entries each, index j k^2 + dy k + dx).
constexpr const char* kScratch = R"(
// Scratch planes (full resolution) that pass A leaves for B and C.
const uint kWt = 0u, kWc = 1u, kHwf = 2u, kGrad = 3u, kWfk = 4u, kHr = 5u;
// Gradient-grid planes: parity p holds gradient.t1..t3 at 4p + 0..2 and w_f at 4p + 3; grad_smooth at 8.
const uint kGradSmooth = 8u;
)";

constexpr const char* kPassADecl = R"(
uniform bool u_history, u_use_ids, u_warped;
uniform float u_tol, u_warped_tol;
uniform int u_gs, u_gw, u_gh;
uniform float u_inv_gs, u_gamma, u_cap, u_floor_g;
uniform uint u_gn, u_wf_prv, u_hw_prv;  // grid plane size, plane bases of w_f and h_w of the previous frame
uniform float u_luma[16];
#define REPROJECT_PREV_Z(q) prevg[uint(q)]
#define REPROJECT_PREV_ID(q) prevg_u[u_n + uint(q)]
)";

constexpr const char* kPassAMain = R"(
// kernel_exp2 of herzog_impl.inc in its steps: the clamp to [-126, 0] on the bits, floor, 1 + f q(f) (kKernelExp2,
// Horner's rule; the driver may fuse the multiply-adds as the v3 and v4 copies do), the exponent built in the bits.
float kernel_exp2(float x) {
  uint u = floatBitsToUint(x);
  u &= uint(int(u) >> 31);
  u = u < 0xC2FC0000u ? u : 0xC2FC0000u;
  x = uintBitsToFloat(u);
  const float t = float(int(x));
  const float xi = t > x ? t - 1.0 : t;
  const float f = x - xi;
  const float p = 1.0 + f * (kQ4 + f * (kQ3 + f * (kQ2 + f * (kQ1 + f * kQ0))));
  const float scale = uintBitsToFloat(uint(int(xi) + 127) << 23);
  return p * scale;
}

// relative_gradient (history.h).
float relative_gradient(float cur, float prev) {
  const float m = std_max(abs(cur), abs(prev));
  return m > 0.0 ? (cur - prev) / m : 0.0;
}

void main() {
  ivec2 p;
  uint i;
  const bool inside = pixel_index(p, i);
  count_begin();
  if (inside) {
    // kernel_falloff_row: the previous w_f at the motion-compensated cell (the off-screen rule in the grid).
    float ek = u_floor_g, wfk = 0.0;
    const float mx = gb[4u * u_n + i], my = gb[5u * u_n + i];
    if (u_history) {
      float px = (float(p.x) + 0.5 + mx) * u_inv_gs, py = (float(p.y) + 0.5 + my) * u_inv_gs;
      const bool in_ = px >= 0.0 && py >= 0.0 && px < float(u_gw) && py < float(u_gh);  // false for NaN
      px = in_ ? px : 0.0;
      py = in_ ? py : 0.0;
      wfk = in_ ? grid[u_wf_prv + uint(int(py) * u_gw + int(px))] : 0.0;
      const float kg = u_gamma * wfk;
      ek = std_max(u_floor_g, u_cap < kg ? u_cap : kg);  // section 3.5, floored
    }
    // spatial_estimate_row: the four taps' geometric weights (expanded_geometric_weights), w~' with the sharp
    // kernel, then the adaptive kernel hat * 2^(ek log2 base) (eq. 3) and w~.
    const int k = u_k, lw = u_low.x, lh = u_low.y;
    const int x0 = floor_div(p.x - u_sx, k), y0 = floor_div(p.y - u_sy, k);
    const int dx = p.x - u_sx - k * x0, dy = p.y - u_sy - k * y0;
    const float cv0 = (x0 >= 0 && x0 < lw) ? 1.0 : 0.0, cv1 = (x0 + 1 >= 0 && x0 + 1 < lw) ? 1.0 : 0.0;
    const float vy0 = (y0 >= 0 && y0 < lh) ? 1.0 : 0.0, vy1 = (y0 + 1 >= 0 && y0 + 1 < lh) ? 1.0 : 0.0;
    const uint ci0 = uint(clamp(x0, 0, lw - 1)), ci1 = uint(clamp(x0 + 1, 0, lw - 1));
    const uint r0 = uint(clamp(y0, 0, lh - 1)) * uint(lw), r1 = uint(clamp(y0 + 1, 0, lh - 1)) * uint(lw);
    const float zi = gb[i], ax = gb[u_n + i], ay = gb[2u * u_n + i], az = gb[3u * u_n + i];
    uint q[4];
    q[0] = r0 + ci0;
    q[1] = r0 + ci1;
    q[2] = r1 + ci0;
    q[3] = r1 + ci1;
    float w[4];
    w[0] = sample_weight_at(q[0], zi, ax, ay, az) * cv0 * vy0;
    w[1] = sample_weight_at(q[1], zi, ax, ay, az) * cv1 * vy0;
    w[2] = sample_weight_at(q[2], zi, ax, ay, az) * cv0 * vy1;
    w[3] = sample_weight_at(q[3], zi, ax, ay, az) * cv1 * vy1;
    const uint kk = uint(k * k), cell = uint(dy * k + dx);
    const float wc = w[0] * tab[kk * 4u + cell] + w[1] * tab[kk * 5u + cell] + w[2] * tab[kk * 6u + cell] +
                     w[3] * tab[kk * 7u + cell];
    for (int j = 0; j < 4; ++j)
      w[j] = w[j] * (tab[kk * uint(8 + j) + cell] * kernel_exp2(ek * tab[kk * uint(j) + cell]));
    const float wt = w[0] + w[1] + w[2] + w[3];
    float yc = 0.0;
    for (int c = 0; c < u_C; ++c) {  // eq. 6; an invalid sample's value (maybe NaN) is replaced by 0
      const uint b = uint(c) * u_ln;
      const float la = lowb[b + q[0]], lb = lowb[b + q[1]], lc = lowb[b + q[2]], ld = lowb[b + q[3]];
      const float a = w[0] > 0.0 ? la : 0.0, bb = w[1] > 0.0 ? lb : 0.0;
      const float cc = w[2] > 0.0 ? lc : 0.0, d = w[3] > 0.0 ? ld : 0.0;
      const float v = w[0] * a + w[1] * bb + w[2] * cc + w[3] * d;
      const float h = wt > 0.0 ? v / wt : 0.0;
      outb[uint(c) * u_n + i] = h;
      yc += u_luma[c] * h;
    }
    // history_gradient_row: h_w and h_r at i(t-1), and the relative gradient of the luminance.
    float hwf = 0.0, g = kMaxGradient;
    bool hit = false;
    if (u_history) {
      Taps t = reproject_taps(p, vec2(mx, my));
      const float z = expect_depth(zi, gb[6u * u_n + i], u_warped);
      hit = reproject_test(t, z, gb_u[7u * u_n + i], true, u_use_ids, expect_tolerance(u_tol, u_warped_tol, u_warped));
      hwf = REPROJECT_GATHER(hwb, u_hw_prv, t);  // 0 on a miss (every weight 0), as gather_row
      float yp = 0.0;
      for (int c = 0; c < u_C; ++c) {
        const float hr = REPROJECT_GATHER(hist, uint(c) * u_n, t);
        scr[(kHr + uint(c)) * u_n + i] = hr;
        yp += u_luma[c] * hr;
      }
      const float rg = clamp(relative_gradient(yc, yp), -kMaxGradient, kMaxGradient);
      // Disoccluded (no history) or no spatial sample: the maximum gradient (Figure 6).
      g = (hit && wt > 0.0) ? rg : kMaxGradient;
    } else {
      for (int c = 0; c < u_C; ++c) scr[(kHr + uint(c)) * u_n + i] = 0.0;
    }
    scr[kWt * u_n + i] = wt;
    scr[kWc * u_n + i] = wc;
    scr[kHwf * u_n + i] = hwf;
    scr[kGrad * u_n + i] = g;
    scr[kWfk * u_n + i] = wfk;
    count_add(0, hit);
  }
  count_end();
}
)";

// Pass B on the gradient grid (dispatch GW x GH, u_size = the grid): scr (5) A's gradients; gb (0) the motion;
// grid (7); pyr (9) level 0 of the pyramid, written.
constexpr const char* kPassB = R"(
uniform ivec2 u_full;
uniform uint u_n, u_gn, u_cur, u_prv;  // full plane size, grid plane size, plane bases of both parities
uniform int u_gs;
uniform bool u_history, u_filter_none;

void main() {
  ivec2 p;
  uint i;
  if (!pixel_index(p, i)) return;
  const int W = u_full.x, H = u_full.y, GW = u_size.x, GH = u_size.y, gs = u_gs;
  // accumulate_gradient_row: per full row of the cell the row's sum (from 0, left to right), added in row order.
  float dc = 0.0, dn = 0.0;
  for (int Y = p.y * gs; Y < min(H, p.y * gs + gs); ++Y) {
    const int X0 = p.x * gs, X1 = min(W, p.x * gs + gs);
    float sum = 0.0;
    for (int X = X0; X < X1; ++X) sum += scr[kGrad * u_n + uint(Y * W + X)];
    dc += sum;
    dn += float(X1 - X0);
  }
  // temporal_filter_row: the previous gradients at the cell centre's motion (nearest cell; none off the grid).
  const int cy = min(H - 1, p.y * gs + gs / 2), cx = min(W - 1, p.x * gs + gs / 2);
  const uint cp = uint(cy * W + cx);
  const float fgs = float(gs);
  const float px = (float(cx) + 0.5 + gb[4u * u_n + cp]) / fgs, py = (float(cy) + 0.5 + gb[5u * u_n + cp]) / fgs;
  const bool in_ = u_history && px >= 0.0 && py >= 0.0 && px < float(GW) && py < float(GH);  // false for NaN
  const uint q = in_ ? uint(int(py) * GW + int(px)) : 0u;
  const float d0 = dn > 0.0 ? dc / dn : kMaxGradient;
  const float d1 = in_ ? grid[u_prv + q] : kMaxGradient;
  const float d2 = in_ ? grid[u_prv + u_gn + q] : kMaxGradient;
  const float d3 = in_ ? grid[u_prv + 2u * u_gn + q] : kMaxGradient;
  grid[u_cur + i] = d0;
  grid[u_cur + u_gn + i] = d1;
  grid[u_cur + 2u * u_gn + i] = d2;
  // filtered_gradient, each product rounded before the sum (herzog.cpp: fp-contract=off).
  precise float s0 = kG0 * d0;
  precise float s1 = kG1 * d1;
  precise float s2 = kG2 * d2;
  precise float s3 = kG3 * d3;
  precise float gf = abs(((s0 + s1) + s2) + s3);
  pyr[i] = u_filter_none ? abs(d0) : gf;  // --gradient-filter none: |g_t|
}
)";

// Pyramid level j from level j - 1 (dispatch at level j's size): 2x2 box with clamp-to-edge (pyramid_row).
constexpr const char* kPyramid = R"(
uniform ivec2 u_src;
void main() {
  ivec2 p;
  uint i;
  if (!pixel_index(p, i)) return;
  const int pw = u_src.x, ph = u_src.y;
  const int ya = min(2 * p.y, ph - 1), yb = min(2 * p.y + 1, ph - 1);
  const int xa = min(2 * p.x, pw - 1), xb = min(2 * p.x + 1, pw - 1);
  pyrb[i] = 0.25 * (pyr[ya * pw + xa] + pyr[ya * pw + xb] + pyr[yb * pw + xa] + pyr[yb * pw + xb]);
}
)";

// The low-pass and eq. 8 on the gradient grid (dispatch GW x GH): levels l0 (pyr, 9) and l0 + 1 (pyrb, 10)
// sampled as resample_columns / lerp_rows do (Axis taps, the same fma()s), blended by frac; grid (7) written.
constexpr const char* kLowPass = R"(
uniform ivec2 u_l0_size, u_l1_size;
uniform float u_l0_scale, u_l1_scale, u_frac_level, u_a, u_fixed_wf;
uniform int u_nlev;
uniform uint u_gn, u_cur;

// Axis::build for one output index: clamp-to-edge bilinear taps at texel centres.
void axis(int g, int n_in, float sc, out int x0, out int x1, out float a) {
  const float u = clamp((float(g) + 0.5) / sc - 0.5, 0.0, float(n_in - 1));
  x0 = min(int(u), n_in - 1);
  x1 = min(x0 + 1, n_in - 1);
  a = u - float(x0);
}

#define SAMPLE_LEVEL(result, buf, size, scale)                                            \
  {                                                                                       \
    int x0_, x1_, y0_, y1_;                                                               \
    float ax_, ay_;                                                                       \
    axis(p.x, size.x, scale, x0_, x1_, ax_);                                              \
    axis(p.y, size.y, scale, y0_, y1_, ay_);                                              \
    precise float h0_ = fma(1.0 - ax_, buf[y0_ * size.x + x0_], ax_ * buf[y0_ * size.x + x1_]); \
    precise float h1_ = fma(1.0 - ax_, buf[y1_ * size.x + x0_], ax_ * buf[y1_ * size.x + x1_]); \
    precise float r_ = fma(1.0 - ay_, h0_, ay_ * h1_);                                    \
    result = r_;                                                                          \
  }

void main() {
  ivec2 p;
  uint i;
  if (!pixel_index(p, i)) return;
  float g0, g1 = 0.0;
  SAMPLE_LEVEL(g0, pyr, u_l0_size, u_l0_scale)
  if (u_nlev == 2) SAMPLE_LEVEL(g1, pyrb, u_l1_size, u_l1_scale)
  // low_pass_row's blend of the two levels: written as GCC contracts it (the first product fused).
  const float g = u_nlev == 2 ? fma(1.0 - u_frac_level, g0, u_frac_level * g1) : g0;
  grid[kGradSmooth * u_gn + i] = g;
  // Eq. 8 (temporal_weight): w_f = a (1 - min(|g|, 1))^2.
  const float m = min(abs(g), 1.0);
  const float wf = u_a * (1.0 - m) * (1.0 - m);
  grid[u_cur + 3u * u_gn + i] = u_fixed_wf >= 0.0 ? u_fixed_wf : wf;  // --fixed-wf: no adaptation
}
)";

// Pass C (full resolution): eq. 7 and the bounded h_w update (blend_row), the debug planes (debug_row).
constexpr const char* kPassC = R"(
uniform uint u_n, u_gn, u_wf_cur, u_hw_cur;
uniform int u_C, u_gs, u_gw;
uniform float u_max_hw;
uniform bool u_fused, u_debug;

void main() {
  ivec2 p;
  uint i;
  if (!pixel_index(p, i)) return;
  const uint cell = uint((p.y / u_gs) * u_gw + p.x / u_gs);
  // --lagged-wf: eq. 7 with the previous frame's w_f that shaped the kernel (herzog.cpp fused_blend_row).
  const float wf = u_fused ? scr[kWfk * u_n + i] : grid[u_wf_cur + cell];
  const float wt = scr[kWt * u_n + i], wc = scr[kWc * u_n + i], hwf = scr[kHwf * u_n + i];
  const float hist_w = wf * hwf;  // w_f h_w(i(t-1))
  const float s = wc + hist_w;
  float hn = u_max_hw < s ? u_max_hw : s;  // bounded_history_weight
  for (int c = 0; c < u_C; ++c) {
    const uint o = uint(c) * u_n + i;
    const float pc = outb[o], hc = scr[(kHr + uint(c)) * u_n + i];
    const float den = wt + hist_w;
    const float v = den > 0.0 ? (pc * wt + hist_w * hc) / den : pc;  // eq. 7 (history_blend_weighted)
    // Nothing non-finite enters the history: such a pixel restarts with no weight.
    const bool ok = abs(v) <= 3.0e38;  // false for NaN and Inf
    hn = ok ? hn : 0.0;
    outb[o] = ok ? v : 0.0;
  }
  hwb[u_hw_cur + i] = hn;
  if (u_debug) {
    const uint d = uint(u_C) * u_n + i;
    outb[d] = wt;                                  // debug.confidence
    outb[d + u_n] = hwf > 0.0 ? 0.0 : 1.0;         // debug.disocclusion
    outb[d + 2u * u_n] = grid[kGradSmooth * u_gn + cell];  // debug.gradient
    outb[d + 3u * u_n] = wf;                       // debug.wf
    outb[d + 4u * u_n] = hn;                       // debug.historyWeight
    outb[d + 5u * u_n] = hn / u_max_hw;            // debug.convergence
  }
}
)";

// The debug planes after the C payload planes, in pass C's order (herzog.cpp adds them in this order too).
constexpr const char* kDebugNames[6] = {"debug.confidence", "debug.disocclusion", "debug.gradient",
                                        "debug.wf", "debug.historyWeight", "debug.convergence"};
constexpr int kScratchFixed = 5;  // wt, wc, hwf, grad, wfk (then h_r per channel)
constexpr int kGridPlanes = 9;    // 2 x (t1, t2, t3, w_f), grad_smooth

struct Programs {
  gpu::Program a, b, pyramid, low_pass, c;
};

class HerzogStateGpu final : public GpuHistoryState {
 public:
  HerzogStateGpu(std::shared_ptr<gpu::Context> ctx, Programs programs, gpu::ImageBuffer counters, const Geometry& g,
                 const HerzogOptions& ho)
      : GpuHistoryState(std::move(ctx), std::move(counters), g), prog_(std::move(programs)) {
    gs_ = std::max(1, ho.gradient_scale);  // fixed for the state's life (its layout: state_layout)
    GW_ = (g_.W + gs_ - 1) / gs_;
    GH_ = (g_.H + gs_ - 1) / gs_;
  }

  // The planes HerzogState::save writes, from the parity of the last frame.
  void save(Image& state) const override {
    // save() cannot report an error; a failed download leaves the plane out and load() names it.
    if (out_[0].empty()) return;
    save_history(state);
    save_plane(hw_, cur_, state, "history.weight");
    for (int t = 0; t < 4; ++t) save_plane(grid_, 4 * cur_ + t, state, grid_plane_name(t));
    save_previous_geometry(prevg_, has_prev_id_, g_, state);
  }

  Status load(const Image& state) override {
    if (Status s = allocate(); !s) return s;
    cur_ = 1 - cur_;  // as OutputPair::next(): what is loaded is the previous frame of the next run()
    if (Status s = load_history(state); !s) return s;
    if (Status s = load_plane(state, "history.weight", hw_, cur_); !s) return s;
    for (int t = 0; t < 4; ++t)
      if (Status s = load_plane(state, grid_plane_name(t), grid_, 4 * cur_ + t); !s) return s;
    return upload_previous_geometry(state, g_, prevg_, has_prev_id_);
  }

 private:
  // The state file's name of plane t of a parity of grid_: the three gradients, then w_f.
  static std::string grid_plane_name(int t) {
    return t < 3 ? "gradient.t" + std::to_string(t + 1) : "gradient.wf";
  }

  // The buffers of the state's geometry, initialised as HerzogState's constructor initialises its vectors (h_w 0,
  // the gradients kMaxGradient, w_f 0, the output 0).
  Status allocate() {
    if (!out_[0].empty()) return Status::ok();
    const int C = int(g_.channels.size()), W = g_.W, H = g_.H;
    if (Status s = gpu::ImageBuffer::create_all_cleared(ctx_, {{&out_[0], W, H, C + 6},
                                                               {&out_[1], W, H, C + 6},
                                                               {&prevg_, W, H, 2},
                                                               {&scratch_, W, H, kScratchFixed + C},
                                                               {&hw_, W, H, 2},
                                                               {&grid_, GW_, GH_, kGridPlanes}});
        !s)
      return s;
    const std::vector<float> max_gradient(std::size_t(GW_) * GH_, kMaxGradient);
    for (int par = 0; par < 2; ++par)
      for (int t = 0; t < 3; ++t)
        if (Status s = grid_.upload(4 * par + t, max_gradient.data()); !s) return s;
    return Status::ok();
  }

  // build_kernel_tables' three tables (before their expansion to columns), computed on the host with the same
  // calls: log2 of the kernel base, the sharp kernel (w_f = 1), the hat (or 1 with --fallback flat).
  Status upload_tables(const HerzogOptions& ho, int k) {
    const int kk = k * k;
    if (tables_.empty() || tables_.width() != 4 * kk) {
      auto created = gpu::ImageBuffer::create(ctx_, 4 * kk, 1, 3);
      if (!created) return created.error();
      tables_ = std::move(*created);
    }
    const float r = float(k) * std::sqrt(2.0f);
    const bool hat_base = ho.fallback != "flat";
    std::vector<float> logb(std::size_t(4) * kk), hat(logb.size()), ksharp(logb.size());
    for (int j = 0; j < 4; ++j)
      for (int dy = 0; dy < k; ++dy)
        for (int dx = 0; dx < k; ++dx) {
          const float ox = float(dx - k * (j & 1)), oy = float(dy - k * (j >> 1));
          logb[std::size_t(j) * kk + dy * k + dx] =
              std::log2(std::max(kKernelEpsilon, 1.0f - std::sqrt(ox * ox + oy * oy) / r));
          hat[std::size_t(j) * kk + dy * k + dx] = hat_base ? hat_kernel(ox, oy, k) : 1.0f;
        }
    const float gamma_full = kernel_gamma(ho.kernel_gamma, 1.0f, ho.max_kernel_gamma);
    for (std::size_t j = 0; j < logb.size(); ++j) ksharp[j] = hat[j] * std::exp2(gamma_full * logb[j]);
    if (Status s = tables_.upload(0, logb.data()); !s) return s;
    if (Status s = tables_.upload(1, ksharp.data()); !s) return s;
    return tables_.upload(2, hat.data());
  }

  // build_pyramid's levels above the gradient grid; the buffers are kept while the mip level does not change.
  Status prepare_pyramid(const HerzogOptions& ho) {
    const float base_level = std::log2(float(gs_));
    const float rel = std::max(0.0f, ho.gradient_mip_level - base_level);
    l0_ = int(std::floor(rel));
    frac_ = rel - float(l0_);
    const int levels = l0_ + (frac_ > 0 ? 1 : 0);
    nlev_ = frac_ > 0 ? 2 : 1;
    if (int(pyr_.size()) == levels + 1) return Status::ok();
    pyr_.clear();
    pyr_w_.assign(1, GW_);
    pyr_h_.assign(1, GH_);
    for (int j = 1; j <= levels; ++j) {
      pyr_w_.push_back(std::max(1, (pyr_w_.back() + 1) / 2));
      pyr_h_.push_back(std::max(1, (pyr_h_.back() + 1) / 2));
    }
    for (int j = 0; j <= levels; ++j) {
      auto created = gpu::ImageBuffer::create(ctx_, pyr_w_[std::size_t(j)], pyr_h_[std::size_t(j)], 1);
      if (!created) return created.error();
      pyr_.push_back(std::move(*created));
    }
    return Status::ok();
  }

  Status run_gpu(const FrameContext& f, bool history, FrameStats& stats) override {
    const HerzogOptions& ho = herzog_options(*f.options);
    if (Status s = allocate(); !s) return s;
    if (Status s = frame_.upload(ctx_, f, true); !s) return s;
    if (Status s = upload_tables(ho, f.grid.k); !s) return s;
    if (Status s = prepare_pyramid(ho); !s) return s;
    if (Status s = counters_.clear(0, 1); !s) return s;
    cur_ = 1 - cur_;  // OutputPair::next()
    const int prv = 1 - cur_, C = f.C, k = f.grid.k;
    const Options& o = *f.options;
    const reproject::SurfaceTest test = o.surface_test();
    // history_row: ids compared when the options ask for them and both frames have them.
    const bool use_ids = test.use_ids && f.id && has_prev_id_;
    const float max_hw = ho.max_history_weight > 0 ? ho.max_history_weight : 2.0f * float(k * k);
    const std::uint32_t n = std::uint32_t(std::size_t(f.W) * f.H), gn = std::uint32_t(std::size_t(GW_) * GH_);

    bind_history_buffers();
    scratch_.bind(5);
    hw_.bind(6);
    grid_.bind(7);
    tables_.bind(8);
    counters_.bind(15);
    timer_.start();
    // Pass A.
    if (Status s = prog_.a.use(); !s) return s;
    set_joint_bilateral_uniforms(prog_.a, f);
    prog_.a.set("u_history", int(history));
    prog_.a.set("u_use_ids", int(use_ids));
    prog_.a.set("u_warped", int(f.prev_z != nullptr));
    prog_.a.set("u_tol", test.depth_tolerance);
    prog_.a.set("u_warped_tol", o.warped_depth_tolerance);
    prog_.a.set("u_gs", gs_);
    prog_.a.set("u_gw", GW_);
    prog_.a.set("u_gh", GH_);
    prog_.a.set("u_inv_gs", 1.0f / float(gs_));
    prog_.a.set("u_gamma", ho.kernel_gamma);
    prog_.a.set("u_cap", ho.max_kernel_gamma);
    prog_.a.set("u_floor_g", ho.min_kernel_gamma);
    prog_.a.set("u_gn", gn);
    prog_.a.set("u_wf_prv", std::uint32_t(4 * prv + 3) * gn);
    prog_.a.set("u_hw_prv", std::uint32_t(prv) * n);
    set_luma_uniform(prog_.a, f);
    if (Status s = prog_.a.dispatch(f.W, f.H); !s) return s;
    // Pass B: the temporal filter into pyramid level 0.
    pyr_[0].bind(9);
    if (Status s = prog_.b.use(); !s) return s;
    prog_.b.set_int2("u_full", f.W, f.H);
    prog_.b.set("u_n", n);
    prog_.b.set("u_gn", gn);
    prog_.b.set("u_cur", std::uint32_t(4 * cur_) * gn);
    prog_.b.set("u_prv", std::uint32_t(4 * prv) * gn);
    prog_.b.set("u_gs", gs_);
    prog_.b.set("u_history", int(history));
    prog_.b.set("u_filter_none", int(ho.gradient_filter == "none"));
    if (Status s = prog_.b.dispatch(GW_, GH_); !s) return s;
    // The box pyramid, level by level.
    if (pyr_.size() > 1) {
      if (Status s = prog_.pyramid.use(); !s) return s;
      for (std::size_t j = 1; j < pyr_.size(); ++j) {
        pyr_[j - 1].bind(9);
        pyr_[j].bind(10);
        prog_.pyramid.set_int2("u_src", pyr_w_[j - 1], pyr_h_[j - 1]);
        if (Status s = prog_.pyramid.dispatch(pyr_w_[j], pyr_h_[j]); !s) return s;
      }
    }
    // The trilinear sample at the mip level, eq. 8.
    const std::size_t l0 = std::size_t(l0_), l1 = std::size_t(l0_ + nlev_ - 1);
    pyr_[l0].bind(9);
    pyr_[l1].bind(10);
    if (Status s = prog_.low_pass.use(); !s) return s;
    prog_.low_pass.set_int2("u_l0_size", pyr_w_[l0], pyr_h_[l0]);
    prog_.low_pass.set_int2("u_l1_size", pyr_w_[l1], pyr_h_[l1]);
    prog_.low_pass.set("u_l0_scale", float(1 << l0_));
    prog_.low_pass.set("u_l1_scale", float(1 << (l0_ + nlev_ - 1)));
    prog_.low_pass.set("u_frac_level", frac_);
    prog_.low_pass.set("u_a", ho.sensitivity());
    prog_.low_pass.set("u_fixed_wf", ho.fixed_wf);
    prog_.low_pass.set("u_nlev", nlev_);
    prog_.low_pass.set("u_gn", gn);
    prog_.low_pass.set("u_cur", std::uint32_t(4 * cur_) * gn);
    if (Status s = prog_.low_pass.dispatch(GW_, GH_); !s) return s;
    // Pass C.
    if (Status s = prog_.c.use(); !s) return s;
    prog_.c.set("u_n", n);
    prog_.c.set("u_gn", gn);
    prog_.c.set("u_wf_cur", std::uint32_t(4 * cur_ + 3) * gn);
    prog_.c.set("u_hw_cur", std::uint32_t(cur_) * n);
    prog_.c.set("u_C", C);
    prog_.c.set("u_gs", gs_);
    prog_.c.set("u_gw", GW_);
    prog_.c.set("u_max_hw", max_hw);
    prog_.c.set("u_fused", int(ho.lagged_wf));
    prog_.c.set("u_debug", int(f.debug));
    if (Status s = prog_.c.dispatch(f.W, f.H); !s) return s;
    timing_.kernel_ms = timer_.stop_ms();
    timing_.clock = timer_.clock();
    timing_.bytes_moved = bytes_moved(f);

    return finish_frame(f, history, kDebugNames, stats);
  }

  // Every plane each dispatch reads or writes, counted once per dispatch (the scratch planes make a round trip
  // between the passes that herzog.cpp keeps in cache: its streamed_bytes is the lower bound, this the traffic).
  double bytes_moved(const FrameContext& f) const {
    const double full = double(f.W) * f.H * 4.0, low = double(f.lw) * f.lh * 4.0, grid = double(GW_) * GH_ * 4.0;
    const int C = f.C;
    // A: depth, N, motion, warped depth, id; the payload; the previous depth, ids, output and h_w; the previous
    // w_f; writes h~ and the scratch planes.
    const double a = 8 * full + C * low + 2 * full + C * full + full + grid + C * full + (kScratchFixed + C) * full;
    // B: A's gradients, the motion at the cell centres, three previous gradients; writes three and level 0.
    const double b = full + 2 * grid + 3 * grid + 4 * grid;
    double pyramid = 0.0;
    for (std::size_t j = 1; j < pyr_.size(); ++j)
      pyramid += 5.0 * double(pyr_w_[j]) * pyr_h_[j] * 4.0;
    const double low_pass = double(pyr_w_[std::size_t(l0_)]) * pyr_h_[std::size_t(l0_)] * 4.0 + 2 * grid;
    // C: w~, w~', h_w fetched, h_r and h~ per channel, w_f; writes h and h_w (and the debug planes).
    const double c = 3 * full + 2 * C * full + grid + C * full + full + (f.debug ? 6 * full : 0.0);
    return a + b + pyramid + low_pass + c;
  }

  Programs prog_;
  int gs_ = 1, GW_ = 0, GH_ = 0;
  gpu::ImageBuffer scratch_, hw_, grid_, tables_;
  std::vector<gpu::ImageBuffer> pyr_;
  std::vector<int> pyr_w_, pyr_h_;
  int l0_ = 0, nlev_ = 1;
  float frac_ = 0.0f;
};

}  // namespace

Expected<std::unique_ptr<MethodState>> make_herzog_state_gpu(std::shared_ptr<gpu::Context> context,
                                                             const Options& options, const Geometry& geometry) {
  if (Status s = gpu::Context::ensure(context); !s) return s.error();
  const std::string consts = constants();
  auto compile = [&](const char* name, std::vector<std::string_view> parts) -> Expected<gpu::Program> {
    return gpu::Program::compile(context, name, parts);
  };
  // Only gb and prevg need their uint view (ids): one block for each other buffer keeps pass A at 12 storage blocks
  // (two views each would be 19; llvmpipe's GL_MAX_COMPUTE_SHADER_STORAGE_BLOCKS is 16).
  const auto floats = gpu::glsl::float_storage;  // a float-only storage block
  const std::string s0 = gpu::glsl::storage(0, "gb"), s1 = floats(1, "lowb"), s2 = floats(2, "outb"),
                    s3 = floats(3, "hist"), s4 = gpu::glsl::storage(4, "prevg"), s5 = floats(5, "scr"),
                    s6 = floats(6, "hwb"), s7 = floats(7, "grid"), s8 = floats(8, "tab"), s9 = floats(9, "pyr"),
                    s10 = floats(10, "pyrb");
  auto a = compile("herzog pass A", {gpu::glsl::prelude(), consts, kScratch, s0, s1, s2, s3, s4, s5, s6, s7, s8,
                                     joint_bilateral_glsl(), kPassADecl, gpu::glsl::reproject(), kPassAMain});
  if (!a) return a.error();
  auto b = compile("herzog pass B", {gpu::glsl::prelude(), consts, kScratch, s0, s5, s7, s9, kPassB});
  if (!b) return b.error();
  auto pyramid = compile("herzog pyramid", {gpu::glsl::prelude(), s9, s10, kPyramid});
  if (!pyramid) return pyramid.error();
  auto low_pass = compile("herzog low-pass", {gpu::glsl::prelude(), consts, kScratch, s7, s9, s10, kLowPass});
  if (!low_pass) return low_pass.error();
  auto c = compile("herzog pass C", {gpu::glsl::prelude(), consts, kScratch, s2, s5, s6, s7, kPassC});
  if (!c) return c.error();
  auto counters = gpu::ImageBuffer::create(context, 4, 1, 1);
  if (!counters) return counters.error();
  Programs programs{std::move(*a), std::move(*b), std::move(*pyramid), std::move(*low_pass), std::move(*c)};
  return std::unique_ptr<MethodState>(new HerzogStateGpu(std::move(context), std::move(programs),
                                                         std::move(*counters), geometry, herzog_options(options)));
}

}  // namespace temporal::upsample
