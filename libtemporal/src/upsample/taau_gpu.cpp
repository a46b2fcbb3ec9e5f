// `taau` (taau.cpp: FSR 2 / UE4 TAAU after their public descriptions) as two GLSL compute kernels with the same
// steps per pixel and the same state planes (history.<c>, history.weight, lock.lifetime, lock.luma, prev.depth,
// prev.id), so that a state file written by either device resumes on the other:
//  L (low resolution): the samples' luminance and FSR 2's thin features (find_thin_features, thin_feature); each
//    invocation recomputes its 3x3 neighbours' luminance (the same expression, so the same values).
//  P (full resolution): steps 1-5 of taau.cpp's file comment for one pixel (history through the shared GLSL
//    reprojection and its Catmull-Rom fetch, the 3x3 Lanczos-2 reconstruction and box, rectification and
//    accumulation, locks), operation for operation.
// What can differ from the C++: the box weights exp(c d^2) (GLSL exp against std::exp: a few ulps), the velocity
// (sqrt(x^2 + y^2) against std::hypot: an ulp), and a * b + c contracted into an FMA differently by the driver and
// GCC. They move values by float roundings; a decision taken on such a value (a thin feature's luminance ratio
// against 1.05, a lock's luminance change against --lock-luma-change, the Catmull-Rom condition |w - w_raw| <= 1e-5)
// flips only where the value meets its threshold within those roundings. Bounds: docs/gpu.md.
#include "gpu_methods.h"
#include "taau.h"
#include "temporal/gpu/glsl.h"
#include "temporal/gpu/timer.h"

#include <algorithm>
#include <cstdio>
#include <limits>
#include <string>

namespace temporal::upsample {
namespace {

std::string constants() {
  const auto line = gpu::glsl::float_constant;  // "const float NAME = VALUE;", the float exactly
  return line("kLanczosWeightScale", kLanczosWeightScale) + line("kMaxAccumulation", kMaxAccumulation) +
         line("kEpsilon", kEpsilon) + line("kRectifiedAccumulation", kRectifiedAccumulation) +
         line("kSimilarLuma", kSimilarLuma) + line("kFloatMax", std::numeric_limits<float>::max()) + R"(
uniform float u_luma[16];
uniform bool u_locks;

)" + std::string(sampling_grid_glsl());
}

// L: dispatch lw x lh (u_size = the low resolution). lowl (6): plane 0 the luminance, plane 1 the thin features.
constexpr const char* kLowMain = R"(
// find_thin_features' luminance: the payload's luma weights, an invalid sample 0.
float sample_luma(uint q) {
  const bool v = low_valid(q);
  float y = 0.0;
  for (int c = 0; c < u_C; ++c) y += u_luma[c] * (v ? lowb[uint(c) * u_ln + q] : 0.0);
  return y;
}

void main() {
  ivec2 p;
  uint i;
  if (!pixel_index(p, i)) return;
  const int lw = u_low.x, lh = u_low.y;
  const float nucleus = sample_luma(i);
  lowl[i] = nucleus;
  bool thin = false;
  if (u_locks) {  // thin_feature
    float dmin = kFloatMax, dmax = 0.0;
    uint mask = 1u << 4;
    int idx = 0;
    for (int dy = -1; dy <= 1; ++dy)
      for (int dx = -1; dx <= 1; ++dx) {
        if (dx != 0 || dy != 0) {
          const int sx = clamp(p.x + dx, 0, lw - 1), sy = clamp(p.y + dy, 0, lh - 1);
          const float s = sample_luma(uint(sy * lw + sx));
          const float hi = (s < nucleus) ? nucleus : s, lo = (nucleus < s) ? nucleus : s;
          const float diff = hi / lo;
          if (diff > 0.0 && diff < kSimilarLuma) {
            mask |= 1u << uint(idx);
          } else {
            dmin = (s < dmin) ? s : dmin;
            dmax = (dmax < s) ? s : dmax;
          }
        }
        ++idx;
      }
    thin = nucleus > dmax || nucleus < dmin;
    const uint quads[4] = uint[4](0x1Bu, 0x36u, 0xD8u, 0x1B0u);  // {0,1,3,4}, {1,2,4,5}, {3,4,6,7}, {4,5,7,8}
    for (int q = 0; q < 4; ++q)
      if ((mask & quads[q]) == quads[q]) thin = false;
  }
  lowl[u_ln + i] = thin ? 1.0 : 0.0;
}
)";

// P: dispatch W x H. Buffers: gb (0), lowb (1) as GpuFrame; outb (2) the output (C planes, then the 7 debug planes);
// hist (3) the previous output; prevg (4) the previous depth and ids; st (5) the weight, lock lifetime and lock
// luminance of both parities (plane 3 parity + 0..2); lowl (6) from L.
constexpr const char* kPixelDecl = R"(
uniform bool u_history, u_use_ids, u_warped, u_debug, u_catmull_rom;
uniform float u_tol, u_warped_tol;
uniform uint u_st_cur, u_st_prv;  // plane bases of the parities' weight planes in st
uniform float u_scale_influence, u_bias_history, u_lifetime_per_weight;
uniform float u_box_scale, u_lock_luma_change, u_motion_accumulation;
#define REPROJECT_PREV_Z(q) prevg[uint(q)]
#define REPROJECT_PREV_ID(q) prevg_u[u_n + uint(q)]
)";

constexpr const char* kPixelMain = R"(
int floor_div(int a, int b) { return (a >= 0) ? a / b : -((-a + b - 1) / b); }
float std_clamp(float v, float lo, float hi) { return v < lo ? lo : (hi < v ? hi : v); }

// TAAU_C is the payload's channel count, fixed when the program is compiled (make_taau_state_gpu): every
// per-channel array below has that constant size and, once the channel loops are unrolled, constant indices, so it
// can live in registers. (With 16-element arrays, loops bounded by a uniform and the 3x3 samples kept in an array
// indexed by the sample count, the kernel ran from local memory: 4.2 ms at 1280x1024 on an H200, 60x the time its
// bytes take at the device's copy bandwidth, against herzog's 1.8x.)

// to_ycgco_box / from_ycgco_box (core/color.h): R, G, B triples as YCgCo, the channels left over as they are.
void to_box(inout float v[TAAU_C]) {
  for (int c = 0; c + 3 <= TAAU_C; c += 3) {
    const float r = v[c], g = v[c + 1], b = v[c + 2];
    v[c] = 0.25 * r + 0.5 * g + 0.25 * b;
    v[c + 1] = -0.25 * r + 0.5 * g - 0.25 * b;
    v[c + 2] = 0.5 * r - 0.5 * b;
  }
}
void from_box(inout float v[TAAU_C]) {
  for (int c = 0; c + 3 <= TAAU_C; c += 3) {
    const float y = v[c], cg = v[c + 1], co = v[c + 2];
    const float t = y - cg;
    v[c] = t + co;
    v[c + 1] = y + cg;
    v[c + 2] = t - co;
  }
}

// The low-resolution sample (lx, ly) of gather_samples' 3x3 around the nearest one: false where it lies outside the
// image or is invalid; else its squared distance to the output pixel p in output pixels / k, and its payload in the
// box space. Both passes over the samples call it, so they see the same values.
bool box_sample(ivec2 p, int lx, int ly, out float d2, out float v[TAAU_C]) {
  if (ly < 0 || ly >= u_low.y || lx < 0 || lx >= u_low.x) return false;
  const uint s = uint(ly * u_low.x + lx);
  if (!low_valid(s)) return false;
  const float inv_k = 1.0 / float(u_k);
  const float ox = float(u_k * lx + u_sx - p.x) * inv_k, oy = float(u_k * ly + u_sy - p.y) * inv_k;
  d2 = ox * ox + oy * oy;
  for (int c = 0; c < TAAU_C; ++c) v[c] = lowb[uint(c) * u_ln + s];
  to_box(v);
  return true;
}

// FSR 2's Lanczos2ApproxSq (taau.cpp lanczos2_approx_sq).
float lanczos2_approx_sq(float x2) {
  x2 = min(x2, 4.0);
  const float a = 0.4 * x2 - 1.0, b = 0.25 * x2 - 1.0;
  return (25.0 / 16.0 * a * a - (25.0 / 16.0 - 1.0)) * b * b;
}

void main() {
  ivec2 p;
  uint i;
  const bool inside = pixel_index(p, i);
  count_begin();
  if (inside) {
    const int C = TAAU_C, lw = u_low.x, lh = u_low.y, k = u_k, W = u_full.x;
    const float mx = gb[4u * u_n + i], my = gb[5u * u_n + i];
    // Step 1: the history taps (fetch_history_row); every plane gathered with them (0 on a miss).
    bool hit = false;
    Taps t;
    if (u_history) {
      t = reproject_taps(p, vec2(mx, my));
      const float z = expect_depth(gb[i], gb[6u * u_n + i], u_warped);
      hit = reproject_test(t, z, gb_u[7u * u_n + i], true, u_use_ids, expect_tolerance(u_tol, u_warped_tol, u_warped));
    }
    const float velocity = is_finite_bits(mx) && is_finite_bits(my) ? sqrt(mx * mx + my * my) : 0.0;
    // Step 2: the 3x3 samples around the nearest one (gather_samples).
    const int xn = clamp(floor_div(2 * (p.x - u_sx) + k, 2 * k), 0, lw - 1);
    const int yn = clamp(floor_div(2 * (p.y - u_sy) + k, 2 * k), 0, lh - 1);
    const float bias = hit ? u_bias_history : 1.0;
    const float curve = -2.0 - min(1.0, velocity / 50.0);  // fRectificationCurveBias
    float sum[TAAU_C], bsum[TAAU_C], bsq[TAAU_C], lo[TAAU_C], hi[TAAU_C];
    for (int c = 0; c < C; ++c) {
      sum[c] = 0.0;
      bsum[c] = 0.0;
      bsq[c] = 0.0;
      lo[c] = 0.0;
      hi[c] = 0.0;
    }
    float wsum = 0.0, bw = 0.0;
    int samples = 0;
    for (int dy = -1; dy <= 1; ++dy)
      for (int dx = -1; dx <= 1; ++dx) {
        float d2, v[TAAU_C];
        if (!box_sample(p, xn + dx, yn + dy, d2, v)) continue;
        const float wl = lanczos2_approx_sq(d2 * bias * bias);
        const float wb = exp(curve * d2);
        for (int c = 0; c < C; ++c) {
          sum[c] += wl * v[c];
          bsum[c] += wb * v[c];
          lo[c] = samples > 0 ? ((v[c] < lo[c]) ? v[c] : lo[c]) : v[c];
          hi[c] = samples > 0 ? ((hi[c] < v[c]) ? v[c] : hi[c]) : v[c];
        }
        wsum += wl;
        bw += wb;
        ++samples;
      }
    // The variance's second pass over the same samples in the same order (taau.cpp keeps them; here each sample is
    // read and its box weight computed again, the same operations on the same values, instead of an array indexed
    // by the sample count, which a compiler can only place in local memory).
    for (int dy = -1; dy <= 1; ++dy)
      for (int dx = -1; dx <= 1; ++dx) {
        float d2, v[TAAU_C];
        if (!box_sample(p, xn + dx, yn + dy, d2, v)) continue;
        const float wb = exp(curve * d2);
        for (int c = 0; c < C; ++c) {
          const float d = v[c] - bsum[c] / bw;
          bsq[c] += wb * d * d;
        }
      }
    // The history in the box space (step 1's colour filter: Catmull-Rom where the four bilinear taps were kept).
    float hv[TAAU_C];
    for (int c = 0; c < C; ++c) hv[c] = hit ? REPROJECT_GATHER(hist, uint(c) * u_n, t) : 0.0;
    if (hit && u_catmull_rom) {
      const float u = float(p.x) + mx, v = float(p.y) + my;
      const float ax = u - floor(u), ay = v - floor(v);
      const float raw[4] = float[4]((1.0 - ax) * (1.0 - ay), ax * (1.0 - ay), (1.0 - ax) * ay, ax * ay);
      bool full = true;
      for (int j = 0; j < 4; ++j) full = full && abs(t.w[j] - raw[j]) <= 1e-5;
      if (full) {
        const CatmullRom cr = catmull_rom(vec2(u, v));
        for (int c = 0; c < C; ++c) CATMULL_ROM_FETCH(hv[c], hist, uint(c) * u_n, cr)
      }
    }
    to_box(hv);
    float acc = hit ? REPROJECT_GATHER(st, u_st_prv, t) : 0.0;
    float lock = hit ? REPROJECT_GATHER(st, u_st_prv + u_n, t) : 0.0;
    float lock_luma = hit ? REPROJECT_GATHER(st, u_st_prv + 2u * u_n, t) : 0.0;
    // Steps 2-4 (accumulate_pixel, rectify_and_accumulate).
    float result[TAAU_C], recon[TAAU_C];
    float w_new = 0.0, alpha = 0.0, rectified = 0.0;
    if (samples == 0) {
      for (int c = 0; c < C; ++c) result[c] = hv[c];
    } else {
      if (wsum > kEpsilon) {
        for (int c = 0; c < C; ++c) recon[c] = std_clamp(sum[c] / wsum, lo[c], hi[c]);
        w_new = wsum * kLanczosWeightScale;
      } else {
        for (int c = 0; c < C; ++c) recon[c] = bsum[c] / bw;
      }
      if (!hit) {
        for (int c = 0; c < C; ++c) result[c] = recon[c];
        acc = w_new;
        alpha = 1.0;
      } else {
        const float max_acc = kMaxAccumulation + (u_motion_accumulation - kMaxAccumulation) * min(1.0, velocity * 10.0);
        acc = min(acc, max_acc);
        const float s = u_box_scale > 0.0 ? u_box_scale
                                          : u_scale_influence + (1.0 - u_scale_influence) * min(1.0, velocity / 20.0);
        const float lock_keep = u_locks ? std_clamp((lock - 1.0) * 4.0, 0.0, 1.0) : 0.0;
        float keep_all = 1.0;
        for (int c = 0; c < C; ++c) {
          const float mean = bsum[c] / bw;
          const float sigma = sqrt(bsq[c] / bw);
          const float a1 = mean - s * sigma, b1 = mean + s * sigma;
          const float bmin = (lo[c] < a1) ? a1 : lo[c], bmax = (b1 < hi[c]) ? b1 : hi[c];
          const float clamped = std_clamp(hv[c], bmin, bmax);
          const float alo = abs(lo[c]), ahi = abs(hi[c]);
          const float centre = 0.5 * (bmin + bmax), tau = 1e-5 * (1.0 + ((alo < ahi) ? ahi : alo));
          const float ratio = (abs(clamped - centre) + tau) / (abs(hv[c] - centre) + tau);
          const float keep = min(1.0, ratio + lock_keep);
          hv[c] = clamped + (hv[c] - clamped) * keep;
          keep_all = min(keep_all, keep);
        }
        const float acc_min = min(acc, kRectifiedAccumulation);
        acc = acc_min + (acc - acc_min) * keep_all;
        const float a = max(kEpsilon, acc + w_new);
        alpha = w_new / a;
        for (int c = 0; c < C; ++c) result[c] = hv[c] + (recon[c] - hv[c]) * alpha;
        acc = min(a, max_acc);
        rectified = 1.0 - keep_all;
      }
    }
    // Step 5 (update_lock).
    if (u_locks) {
      if (!hit) lock = 0.0;
      float rgb[TAAU_C];
      for (int c = 0; c < C; ++c) rgb[c] = result[c];
      from_box(rgb);
      float yr = 0.0;
      for (int c = 0; c < C; ++c) yr += u_luma[c] * rgb[c];
      if (lock > 0.0) {
        const float ay = abs(yr), al = abs(lock_luma);
        const float m = (ay < al) ? al : ay;
        const float change = m > 0.0 ? abs(yr - lock_luma) / m : 0.0;
        if (change > u_lock_luma_change) lock = 0.0;
      }
      const int dxs = p.x - u_sx, dys = p.y - u_sy;
      if (dxs >= 0 && dys >= 0 && dxs % k == 0 && dys % k == 0 && dxs / k < lw && dys / k < lh) {
        const uint q = uint((dys / k) * lw + dxs / k);
        if (lowl[u_ln + q] > 0.0) {
          lock = lock > 0.0 ? 2.0 : 1.0;
          lock_luma = lowl[q];
        }
      }
      lock = max(0.0, lock - w_new * u_lifetime_per_weight);
    } else {
      lock = 0.0;
    }
    from_box(result);
    bool ok = true;
    for (int c = 0; c < C; ++c) ok = ok && abs(result[c]) <= 3.0e38;  // false for NaN and Inf
    for (int c = 0; c < C; ++c) outb[uint(c) * u_n + i] = ok ? result[c] : 0.0;
    const float acc_out = ok ? acc : 0.0, lock_out = ok ? lock : 0.0;
    st[u_st_cur + i] = acc_out;
    st[u_st_cur + u_n + i] = lock_out;
    st[u_st_cur + 2u * u_n + i] = lock_luma;
    if (u_debug) {
      const uint d = uint(C) * u_n + i;
      outb[d] = w_new;                           // debug.confidence
      outb[d + u_n] = hit ? 0.0 : 1.0;           // debug.disocclusion
      outb[d + 2u * u_n] = rectified;            // debug.gradient
      outb[d + 3u * u_n] = 1.0 - alpha;          // debug.wf
      outb[d + 4u * u_n] = acc_out;              // debug.historyWeight
      outb[d + 5u * u_n] = acc_out / kMaxAccumulation;  // debug.convergence
      outb[d + 6u * u_n] = lock_out;             // debug.lock
    }
    count_add(0, hit);
  }
  count_end();
}
)";

// The state file's names of the planes of a parity of st_ (TaauState::save's).
constexpr const char* kStateNames[3] = {"history.weight", "lock.lifetime", "lock.luma"};
constexpr const char* kDebugNames[7] = {"debug.confidence", "debug.disocclusion", "debug.gradient", "debug.wf",
                                        "debug.historyWeight", "debug.convergence", "debug.lock"};

class TaauStateGpu final : public GpuHistoryState {
 public:
  TaauStateGpu(std::shared_ptr<gpu::Context> ctx, gpu::Program low, gpu::Program pixel, gpu::ImageBuffer counters,
               const Geometry& g)
      : GpuHistoryState(std::move(ctx), std::move(counters), g), low_(std::move(low)), pixel_(std::move(pixel)) {}

  // The planes TaauState::save writes, from the parity of the last frame.
  void save(Image& state) const override {
    if (out_[0].empty()) return;  // save() cannot report an error; load() names a missing plane
    save_history(state);
    for (int q = 0; q < 3; ++q) save_plane(st_, 3 * cur_ + q, state, kStateNames[q]);
    save_previous_geometry(prevg_, has_prev_id_, g_, state);
  }

  Status load(const Image& state) override {
    if (Status s = allocate(); !s) return s;
    cur_ = 1 - cur_;  // OutputPair::next()
    if (Status s = load_history(state); !s) return s;
    for (int q = 0; q < 3; ++q)
      if (Status s = load_plane(state, kStateNames[q], st_, 3 * cur_ + q); !s) return s;
    return upload_previous_geometry(state, g_, prevg_, has_prev_id_);
  }

 private:
  // TaauState's constructor: weights, locks and the outputs 0.
  Status allocate() {
    if (!out_[0].empty()) return Status::ok();
    const int C = int(g_.channels.size()), W = g_.W, H = g_.H;
    return gpu::ImageBuffer::create_all_cleared(ctx_, {{&out_[0], W, H, C + 7},
                                                       {&out_[1], W, H, C + 7},
                                                       {&prevg_, W, H, 2},
                                                       {&st_, W, H, 6},
                                                       {&lowl_, g_.lw, g_.lh, 2}});
  }

  void set_common(const gpu::Program& prog, const FrameContext& f, const TaauOptions& to) const {
    set_sampling_grid_uniforms(prog, f);
    set_luma_uniform(prog, f);
    prog.set("u_locks", int(to.locks));
  }

  Status run_gpu(const FrameContext& f, bool history, FrameStats& stats) override {
    const TaauOptions& to = taau_options(*f.options);
    if (f.C > 16) return Error::usage("taau on the GPU takes at most 16 payload channels, not " + std::to_string(f.C));
    if (f.C != int(g_.channels.size()))  // the pixel kernel was compiled for the state's channel count (TAAU_C)
      return Error::internal("taau on the GPU: a frame of " + std::to_string(f.C) + " channels for a state made for " +
                             std::to_string(g_.channels.size()));
    if (Status s = allocate(); !s) return s;
    if (Status s = frame_.upload(ctx_, f, true); !s) return s;
    if (Status s = counters_.clear(0, 1); !s) return s;
    cur_ = 1 - cur_;  // OutputPair::next()
    const int prv = 1 - cur_, C = f.C;
    const Options& o = *f.options;
    const reproject::SurfaceTest test = o.surface_test();
    const bool use_ids = test.use_ids && f.id && has_prev_id_;  // history_row
    const TaauConstants constants = taau_constants(f.grid.k);
    const std::uint32_t n = std::uint32_t(std::size_t(f.W) * f.H);

    bind_history_buffers();
    st_.bind(5);
    lowl_.bind(6);
    counters_.bind(15);
    timer_.start();
    if (Status s = low_.use(); !s) return s;
    set_common(low_, f, to);
    if (Status s = low_.dispatch(f.lw, f.lh); !s) return s;
    if (Status s = pixel_.use(); !s) return s;
    set_common(pixel_, f, to);
    pixel_.set("u_history", int(history));
    pixel_.set("u_use_ids", int(use_ids));
    pixel_.set("u_warped", int(f.prev_z != nullptr));
    pixel_.set("u_debug", int(f.debug));
    pixel_.set("u_catmull_rom", int(to.history == "catmull-rom"));
    pixel_.set("u_tol", test.depth_tolerance);
    pixel_.set("u_warped_tol", o.warped_depth_tolerance);
    pixel_.set("u_st_cur", std::uint32_t(3 * cur_) * n);
    pixel_.set("u_st_prv", std::uint32_t(3 * prv) * n);
    pixel_.set("u_scale_influence", constants.scale_influence);
    pixel_.set("u_bias_history", constants.bias_history);
    pixel_.set("u_lifetime_per_weight", constants.lifetime_per_weight);
    pixel_.set("u_box_scale", to.box_scale);
    pixel_.set("u_lock_luma_change", to.lock_luma_change);
    pixel_.set("u_motion_accumulation", to.motion_accumulation);
    if (Status s = pixel_.dispatch(f.W, f.H); !s) return s;
    timing_.kernel_ms = timer_.stop_ms();
    timing_.clock = timer_.clock();
    // L: the payload and 9 x 4 geometry values per sample read (cached), luminance and features written; P: taau.cpp's
    // streamed_bytes (+ the debug planes).
    const double full = double(f.W) * f.H * 4.0, low = double(f.lw) * f.lh * 4.0;
    timing_.bytes_moved = (C * low + 4 * low + 2 * low) + 4 * full + C * low + C * full + 2 * full + full +
                          2 * (2 * full) + C * full + 3 * 2 * full + 2 * low + (f.debug ? 7.0 * full : 0.0);

    return finish_frame(f, history, kDebugNames, stats);
  }

  gpu::Program low_, pixel_;
  gpu::ImageBuffer st_, lowl_;
};

}  // namespace

Expected<std::unique_ptr<MethodState>> make_taau_state_gpu(std::shared_ptr<gpu::Context> context, const Options&,
                                                           const Geometry& geometry) {
  if (Status s = gpu::Context::ensure(context); !s) return s.error();
  const auto floats = gpu::glsl::float_storage;  // a float-only storage block
  const std::string consts = constants();
  const std::string s0 = gpu::glsl::storage(0, "gb"), s1 = floats(1, "lowb"), s2 = floats(2, "outb"),
                    s3 = floats(3, "hist"), s4 = gpu::glsl::storage(4, "prevg"), s5 = floats(5, "st"),
                    s6 = floats(6, "lowl");
  auto low = gpu::Program::compile(context, "taau luminance", {gpu::glsl::prelude(), s0, s1, s6, consts, kLowMain});
  if (!low) return low.error();
  // The pixel kernel's per-channel arrays have the payload's channel count as their size (kPixelMain's TAAU_C).
  const std::string channels = "#define TAAU_C " + std::to_string(std::max<std::size_t>(1, geometry.channels.size())) + "\n";
  auto pixel = gpu::Program::compile(context, "taau",
                                     {gpu::glsl::prelude(), s0, s1, s2, s3, s4, s5, s6, consts, channels, kPixelDecl,
                                      gpu::glsl::reproject(), kPixelMain});
  if (!pixel) return pixel.error();
  auto counters = gpu::ImageBuffer::create(context, 4, 1, 1);
  if (!counters) return counters.error();
  return std::unique_ptr<MethodState>(new TaauStateGpu(std::move(context), std::move(*low), std::move(*pixel),
                                                       std::move(*counters), geometry));
}

}  // namespace temporal::upsample
