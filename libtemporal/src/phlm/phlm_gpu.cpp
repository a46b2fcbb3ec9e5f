// PHLM (phlm.cpp, seed 003 Algorithm 1 with rls.h's Bierman update) as one GLSL compute kernel per frame: the 3x3
// neighbourhood (box, luma range, the [1 2 1]^2 low-pass, summed in phlm.cpp's order: columns, then rows), the
// model fetch at p + motion (bilinear, nearest or Catmull-Rom as phlm.cpp), the temporal feature, the box test with
// its ray clip and reset, the RLS update and the prediction, statement for statement. The models are planar on the
// GPU (plane k = element k of phlm.cpp's record, the order of PhlmFilter::state_channel_names), so the state file
// is the same; saved_state() adds the covariance planes through the C++ filter, as PhlmFilter::saved_state does.
#include "gpu_filter.h"
#include "temporal/phlm/gpu_filters.h"
#include "temporal/phlm/phlm.h"
#include "temporal/phlm/rls.h"

#include <cstring>

namespace temporal::phlm {
namespace {

// src (binding 0): colour planes 0..C-1, motion.X C, motion.Y C+1; prev (1) / nxt (2): the KSIZE model planes;
// outb (3): the C output planes, then debug.alpha, debug.reset, debug.traceP, debug.feature<c>.
constexpr const char* kPhlmDecl = R"(
const int C = PHLM_C;
const int N = C + 1;
const int KOFF = N * (N - 1) / 2;
const int KBETA = 0, KD = C * N, KU = KD + N, KFEATURE = KU + KOFF, KSCALE = KFEATURE + C, KSIZE = KSCALE + 1;
const float kMinD = 1e-20;
uniform uint u_n;
uniform bool u_motion, u_have_prev, u_reset_all, u_feature, u_box_test, u_alpha_eq1, u_phi_linear, u_debug;
uniform int u_fetch;  // 0 bilinear, 1 nearest, 2 Catmull-Rom
uniform float u_p0, u_trace_max, u_a, u_b, u_lambda;
#define PL(k) (uint(k) * u_n)

float luma(float v[C]) {
#if PHLM_C == 3
  return 0.25 * v[0] + 0.5 * v[1] + 0.25 * v[2];
#else
  return v[0];
#endif
}
float model_scale(float c[C]) { return max_(1.0, abs(luma(c))); }

// rls.h
int off_index(int i, int j) { return i * N - i * (i + 1) / 2 + (j - i - 1); }
struct Model {
  float beta[C * N];
  float u[KOFF];
  float d[N];
};
void rls_reset(inout Model m, float value[C], float p0) {
  for (int c = 0; c < C; ++c) {
    m.beta[c * N] = value[c];
    for (int k = 1; k < N; ++k) m.beta[c * N + k] = 0.0;
  }
  for (int k = 0; k < KOFF; ++k) m.u[k] = 0.0;
  for (int k = 0; k < N; ++k) m.d[k] = p0;
}
float rls_predict(Model m, int c, float x[N]) {
  float s = 0.0;
  for (int k = 0; k < N; ++k) s += m.beta[c * N + k] * x[k];
  return s;
}
float rls_trace(Model m) {
  float t = 0.0;
  for (int j = 0; j < N; ++j) {
    float col = 1.0;
    for (int i = 0; i < j; ++i) col += m.u[off_index(i, j)] * m.u[off_index(i, j)];
    t += m.d[j] * col;
  }
  return t;
}
void bierman_update(inout Model m, float x[N], float r, out float gain[N]) {
  float f[N], v[N];
  for (int j = 0; j < N; ++j) {
    float s = x[j];
    for (int i = 0; i < j; ++i) s += m.u[off_index(i, j)] * x[i];
    f[j] = s;
    v[j] = m.d[j] * s;
  }
  float alpha[N], inv[N];
  alpha[0] = r + v[0] * f[0];
  for (int j = 1; j < N; ++j) alpha[j] = alpha[j - 1] + v[j] * f[j];
  for (int j = 0; j < N; ++j) inv[j] = 1.0 / alpha[j];
  m.d[0] *= r * inv[0];
  gain[0] = v[0];
  for (int j = 1; j < N; ++j) {
    const float p = -f[j] * inv[j - 1];
    m.d[j] *= alpha[j - 1] * inv[j];
    for (int i = 0; i < j; ++i) {
      const int k = off_index(i, j);
      const float old = m.u[k];
      m.u[k] = old + gain[i] * p;
      gain[i] += old * v[j];
    }
    gain[j] = v[j];
  }
  for (int j = 0; j < N; ++j) gain[j] *= inv[N - 1];
}
float rls_update(inout Model m, float x[N], float y[C], float lambda, float d_max, float trace_max) {
  float e[C];
  for (int c = 0; c < C; ++c) e[c] = y[c] - rls_predict(m, c, x);
  float gain[N];
  bierman_update(m, x, lambda, gain);
  for (int c = 0; c < C; ++c)
    for (int k = 0; k < N; ++k) m.beta[c * N + k] += gain[k] * e[c];
  const float inv_lambda = 1.0 / lambda;
  for (int k = 0; k < N; ++k) m.d[k] = min_(max_(m.d[k] * inv_lambda, kMinD), d_max);
  float t = rls_trace(m);
  if (t > trace_max) {
    const float scale = trace_max / t;
    for (int k = 0; k < N; ++k) m.d[k] = max_(m.d[k] * scale, kMinD);
    t = rls_trace(m);
  }
  return t;
}

bool valid_at(uint q) {
  bool ok = true;
  for (int c = 0; c < C; ++c) ok = ok && is_sample(src[PL(c) + q]);
  return ok;
}
)";

constexpr const char* kPhlmMain = R"(
void main() {
  ivec2 p;
  uint i;
  const bool inside = pixel_index(p, i);
  count_begin();
  if (inside) {
    const int w = u_size.x, h = u_size.y, xx = p.x, yy = p.y;
    const float inf = uintBitsToFloat(0x7f800000u);
    // The 3x3 neighbourhood as phlm.cpp's separable passes: per column (rows y-1, y, y+1 clamped) the box min /
    // max and the vertical [1 2 1] sums, then across the columns x-1, x, x+1 (clamped: the padding).
    const int rows[3] = int[3](max(yy - 1, 0), yy, min(yy + 1, h - 1));
    float vw[3], vmin[3 * C], vmax[3 * C], vlow[3 * C];
    for (int k = 0; k < 3; ++k) {
      const int x = clamp(xx - 1 + k, 0, w - 1);
      bool va[3];
      for (int j = 0; j < 3; ++j) va[j] = valid_at(uint(rows[j]) * uint(w) + uint(x));
      vw[k] = (va[0] ? 1.0 : 0.0) + (va[1] ? 2.0 : 0.0) + (va[2] ? 1.0 : 0.0);
      float yv[3][C], bv[3][C];
      for (int j = 0; j < 3; ++j) {
        const uint q = uint(rows[j]) * uint(w) + uint(x);
        float v[C];
        for (int c = 0; c < C; ++c) v[c] = src[PL(c) + q];
        float b[C];
        to_box(v, b);
        yv[j] = v;
        bv[j] = b;
      }
      for (int c = 0; c < C; ++c) {
        vmin[k * C + c] = min_(min_(va[0] ? bv[0][c] : inf, va[1] ? bv[1][c] : inf), va[2] ? bv[2][c] : inf);
        vmax[k * C + c] = max_(max_(va[0] ? bv[0][c] : -inf, va[1] ? bv[1][c] : -inf), va[2] ? bv[2][c] : -inf);
        vlow[k * C + c] = (va[0] ? yv[0][c] : 0.0) + 2.0 * (va[1] ? yv[1][c] : 0.0) + (va[2] ? yv[2][c] : 0.0);
      }
    }
    const float hw = vw[0] + 2.0 * vw[1] + vw[2];
    float bmin[C], bmax[C], low[C], yc[C];
    for (int c = 0; c < C; ++c) {
      bmin[c] = min_(min_(vmin[c], vmin[C + c]), vmin[2 * C + c]);
      bmax[c] = max_(max_(vmax[c], vmax[C + c]), vmax[2 * C + c]);
      low[c] = hw > 0.0 ? (vlow[c] + 2.0 * vlow[C + c] + vlow[2 * C + c]) / hw : 0.0;
      yc[c] = src[PL(c) + i];
    }
    const bool any_valid = hw > 0.0;
    const bool centre_valid = valid_at(i);

    const float mvx = u_motion ? src[PL(C) + i] : 0.0;
    const float mvy = u_motion ? src[PL(C + 1) + i] : 0.0;
    const vec2 fpos = vec2(float(xx) + mvx, float(yy) + mvy);
    const bool reset = u_reset_all || !u_have_prev || !reproject_on_screen(fpos);
    float rec[KSIZE];
    if (!reset && u_fetch == 1) {
      const uint q = uint(reproject_nearest(fpos));
      for (int k = 0; k < KSIZE; ++k) rec[k] = prev[PL(k) + q];
    } else if (!reset) {
      const Taps bl = reproject_bilinear(fpos);
      if (bl.w[0] == 1.0) {
        for (int k = 0; k < KSIZE; ++k) rec[k] = prev[PL(k) + uint(bl.q[0])];
      } else {
        for (int k = 0; k < KSIZE; ++k) rec[k] = REPROJECT_GATHER(prev, PL(k), bl);
      }
      if (u_fetch == 2) {
        const CatmullRom cr = catmull_rom(fpos);
        float acc[C * N + C];
        for (int e = 0; e < C * N + C; ++e) acc[e] = 0.0;
        for (int j = 0; j < 4; ++j)
          for (int k = 0; k < 4; ++k) {
            const float wt = cr.wy[j] * cr.wx[k];
            const uint q = uint(cr.row[j] + cr.col[k]);
            for (int e = 0; e < C * N; ++e) acc[e] += wt * prev[PL(KBETA + e) + q];
            for (int c = 0; c < C; ++c) acc[C * N + c] += wt * prev[PL(KFEATURE + c) + q];
          }
        for (int e = 0; e < C * N; ++e) rec[KBETA + e] = acc[e];
        for (int c = 0; c < C; ++c) rec[KFEATURE + c] = acc[C * N + c];
      }
    }

    float z[C];
    float alpha = 1.0;
    if (reset) {
      for (int c = 0; c < C; ++c) z[c] = centre_valid ? yc[c] : low[c];
    } else {
      float zh[C];
      for (int c = 0; c < C; ++c) zh[c] = rec[KFEATURE + c];
      if (!any_valid) {
        for (int c = 0; c < C; ++c) z[c] = zh[c];
        alpha = 0.0;
      } else {
        const float k = 1.0 / max_(1.0, abs(luma(low)));
        const float lh = luma(zh);
        const float delta = (bmax[0] - bmin[0]) * k;
        const float l = min_(abs(lh - bmin[0]), abs(lh - bmax[0])) * k;
        const float v = sqrt(mvx * mvx + mvy * mvy);
        // phlm.cpp update_feature: section 5.1 as printed, or the linear (UE4 HistoryFactor) form.
        const float phi = u_phi_linear ? (u_a + u_b * v) * l : u_a * l * l + u_b * v * l * l * l;
        const float den = l + delta;
        alpha = den > 0.0 ? min_(phi / den, 1.0) : 0.0;
        float zb[C];
        to_box(zh, zb);
        for (int c = 0; c < C; ++c) zb[c] = min(max(zb[c], bmin[c]), bmax[c]);  // std::clamp
        from_box(zb, zh);
        if (u_alpha_eq1)
          for (int c = 0; c < C; ++c) z[c] = low[c] + alpha * (zh[c] - low[c]);
        else
          for (int c = 0; c < C; ++c) z[c] = zh[c] + alpha * (low[c] - zh[c]);
      }
    }

    Model m;
    float s;
    float flag = 0.0;
    if (reset) {
      float c0[C];
      for (int c = 0; c < C; ++c) c0[c] = centre_valid ? yc[c] : z[c];
      s = model_scale(c0);
      float v0[C];
      for (int c = 0; c < C; ++c) v0[c] = c0[c] / s;
      rls_reset(m, v0, u_p0);
      flag = 1.0;
    } else {
      for (int e = 0; e < C * N; ++e) m.beta[e] = rec[KBETA + e];
      for (int k = 0; k < KOFF; ++k) m.u[k] = rec[KU + k];
      for (int k = 0; k < N; ++k) m.d[k] = rec[KD + k];
      s = rec[KSCALE];
    }
    float x[N];
    x[0] = 1.0;
    for (int c = 0; c < C; ++c) x[c + 1] = u_feature ? z[c] / s : 0.0;

    float trace_p = 0.0;
    bool clamped = false;
    if (centre_valid) {
      float f[C], fb[C], yb[C];
      for (int c = 0; c < C; ++c) f[c] = s * rls_predict(m, c, x);
      to_box(f, fb);
      to_box(yc, yb);
      bool inside_box = true;
      for (int c = 0; c < C; ++c) inside_box = inside_box && fb[c] >= bmin[c] && fb[c] <= bmax[c];
      inside_box = inside_box || !u_box_test;
      if (!inside_box) {
        bool finite = true;
        for (int c = 0; c < C; ++c) finite = finite && is_finite_bits(fb[c]);
        float t_hit = 1.0;
        if (finite) {
          float t_near = 0.0;
          for (int c = 0; c < C; ++c) {
            const float dir = yb[c] - fb[c];
            if (dir == 0.0) continue;
            const float t0 = (bmin[c] - fb[c]) / dir, t1 = (bmax[c] - fb[c]) / dir;
            t_near = max_(t_near, min_(t0, t1));
          }
          t_hit = min_(t_near, 1.0);
        }
        for (int c = 0; c < C; ++c) fb[c] = finite ? fb[c] + t_hit * (yb[c] - fb[c]) : yb[c];
        from_box(fb, f);
        s = model_scale(f);
        float v0[C];
        for (int c = 0; c < C; ++c) v0[c] = f[c] / s;
        rls_reset(m, v0, u_p0);
        for (int c = 0; c < C; ++c) x[c + 1] = u_feature ? z[c] / s : 0.0;
        flag = 2.0;
        clamped = true;
      }
      float yn[C];
      for (int c = 0; c < C; ++c) yn[c] = yc[c] / s;
      trace_p = rls_update(m, x, yn, u_lambda, u_p0, u_trace_max);
    } else {
      trace_p = rls_trace(m);
    }

    {
      float f[C];
      for (int c = 0; c < C; ++c) f[c] = s * rls_predict(m, c, x);
      if (!centre_valid && any_valid) {
        float fb[C];
        to_box(f, fb);
        for (int c = 0; c < C; ++c) fb[c] = is_finite_bits(fb[c]) ? min(max(fb[c], bmin[c]), bmax[c]) : bmin[c];
        from_box(fb, f);
      }
      for (int c = 0; c < C; ++c) outb[PL(c) + i] = f[c];
    }
    for (int e = 0; e < C * N; ++e) nxt[PL(KBETA + e) + i] = m.beta[e];
    for (int k = 0; k < KOFF; ++k) nxt[PL(KU + k) + i] = m.u[k];
    for (int k = 0; k < N; ++k) nxt[PL(KD + k) + i] = m.d[k];
    for (int c = 0; c < C; ++c) nxt[PL(KFEATURE + c) + i] = z[c];
    nxt[PL(KSCALE) + i] = s;
    if (u_debug) {
      outb[PL(C) + i] = alpha;
      outb[PL(C + 1) + i] = flag;
      outb[PL(C + 2) + i] = trace_p;
      for (int c = 0; c < C; ++c) outb[PL(C + 3 + c) + i] = z[c];
    }
    count_add(0, reset);
    count_add(1, clamped);
    count_add(2, !centre_valid);
    // The largest trace(P) (positive floats order like their bits).
    atomicMax(counters[3], floatBitsToUint(max_(trace_p, 0.0)));
  }
  count_end();
}
)";

class PhlmFilterGpu final : public detail::GpuFilter {
 public:
  PhlmFilterGpu(std::shared_ptr<gpu::Context> ctx, PhlmParams params, gpu::Program programs[2],
                gpu::ImageBuffer counters)
      : GpuFilter(std::move(ctx), std::move(counters)), params_(std::move(params)) {
    programs_[0] = std::move(programs[0]);
    programs_[1] = std::move(programs[1]);
  }

  Status process(const FilterInput& in, Image& output, FilterStats* stats) override {
    if (Status s = validate_filter_input(in); !s) return s;
    const int C = int(in.channels.size());
    const int w = in.color->width(), h = in.color->height();
    const bool same = have_state_ && C == channels_ && state_[0].width() == w && state_[0].height() == h;
    if (!same)
      if (Status s = allocate(C, w, h); !s) return s;
    if (Status s = upload_colour(in, src_, true); !s) return s;
    if (Status s = counters_.clear(0, 1); !s) return s;
    const int n = C + 1;
    const gpu::Program& program = programs_[C == 3 ? 1 : 0];
    if (Status s = program.use(); !s) return s;
    program.set("u_n", std::uint32_t(src_.pixel_count()));
    program.set("u_motion", int(in.motion_x != nullptr));
    program.set("u_have_prev", int(same));
    program.set("u_reset_all", int(in.reset));
    program.set("u_feature", int(!params_.no_feature));
    program.set("u_box_test", int(!params_.no_box_test));
    program.set("u_alpha_eq1", int(params_.alpha_reading == "eq1"));
    program.set("u_phi_linear", int(params_.feature_phi == "linear"));
    program.set("u_debug", int(in.debug));
    program.set("u_fetch", fetch_ == HistoryFetch::Bilinear ? 0 : fetch_ == HistoryFetch::Nearest ? 1 : 2);
    program.set("u_p0", params_.p_init);
    program.set("u_trace_max", params_.trace_factor * float(n) * params_.p_init);
    program.set("u_a", params_.feature_a);
    program.set("u_b", params_.feature_b);
    program.set("u_lambda", params_.lambda);
    src_.bind(0);
    state_[cur_].bind(1);
    state_[1 - cur_].bind(2);
    out_.bind(3);
    if (Status s = timed([&] { return program.dispatch(w, h); }); !s) return s;
    // Colour and motion read, the models read and written once each (26 floats per pixel for RGB), output written.
    const int k = phlm_state_floats(C);
    timing_.bytes_moved = double(src_.pixel_count()) * 4.0 *
                          (C + (in.motion_x ? 2 : 0) + (same ? k : 0) + k + C + (in.debug ? 3 + C : 0));

    static const char* const kDebugNames[3] = {"debug.alpha", "debug.reset", "debug.traceP"};
    if (Status s = download_output(in, output, out_, C, kDebugNames); !s) return s;
    if (in.debug) {
      for (int c = 0; c < C; ++c) {
        const std::string name =
            C == 3 ? "debug.feature" + std::string(detail::channel_suffix(3, c)) : std::string("debug.feature");
        if (Status s = out_.download(C + 3 + c, output.add_channel(name)); !s) return s;
      }
    }
    cur_ = 1 - cur_;
    have_state_ = true;
    if (stats) {
      std::uint32_t counts[4] = {};
      if (Status s = counters_.download(0, counts); !s) return s;
      stats->non_finite = counts[2];
      stats->history_resets = counts[0];
      stats->clamped = counts[1];
      float max_trace;
      std::memcpy(&max_trace, &counts[3], sizeof max_trace);
      stats->max_trace_p = max_trace;
    }
    return Status::ok();
  }

  // PhlmFilter::saved_state: the model planes and the covariance P = U D U^T for inspection (computed by the C++
  // filter from the downloaded planes).
  Image saved_state() const override {
    if (!have_state_) return {};
    Image planes(state_[cur_].width(), state_[cur_].height());
    const auto names = PhlmFilter::state_channel_names(channels_);
    for (int k = 0; k < int(names.size()); ++k)
      if (!state_[cur_].download(k, planes, names[std::size_t(k)])) return {};
    PhlmFilter cpu(params_);
    if (!cpu.set_state(planes, channels_)) return planes;
    return cpu.saved_state();
  }

  Status set_state(const Image& state, int channels) override {
    PhlmFilter check(params_);  // the C++ filter's checks and messages (missing planes, D and s > 0)
    if (Status s = check.set_state(state, channels); !s) return s;
    if (Status s = allocate(channels, state.width(), state.height()); !s) return s;
    const auto names = PhlmFilter::state_channel_names(channels);
    for (int k = 0; k < int(names.size()); ++k)
      if (Status s = state_[cur_].upload(k, state, names[std::size_t(k)]); !s) return s;
    have_state_ = true;
    return Status::ok();
  }

  std::string stats_text(const FilterStats& stats) const override {
    return ", max trace(P) " + std::to_string(stats.max_trace_p);
  }

  HistoryFetch fetch_ = HistoryFetch::Bilinear;

 private:
  Status allocate(int channels, int w, int h) {
    channels_ = channels;
    const int k = phlm_state_floats(channels);
    if (src_.width() == w && src_.height() == h && state_[0].planes() == k) return Status::ok();
    return gpu::ImageBuffer::create_all(ctx_, {{&src_, w, h, channels + 2},
                                               {&state_[0], w, h, k},
                                               {&state_[1], w, h, k},
                                               {&out_, w, h, 2 * channels + 3}});
  }

  PhlmParams params_;
  gpu::Program programs_[2];  // 1 and 3 channels
  gpu::ImageBuffer src_, state_[2], out_;
  int cur_ = 0, channels_ = 0;
  bool have_state_ = false;
};

}  // namespace

Expected<std::unique_ptr<FrameFilter>> make_phlm_filter_gpu(std::shared_ptr<gpu::Context> context,
                                                           PhlmParams params) {
  if (params.alpha_reading != "ue4" && params.alpha_reading != "eq1")
    return Error::usage("--feature-alpha '" + params.alpha_reading + "' is not one of: ue4, eq1");
  if (params.feature_phi != "paper" && params.feature_phi != "linear")
    return Error::usage("--feature-phi '" + params.feature_phi + "' is not one of: paper, linear");
  auto fetch = parse_history_fetch(params.model_fetch, "--model-fetch");
  if (!fetch) return fetch.error();
  if (Status s = gpu::Context::ensure(context); !s) return s.error();
  gpu::Program programs[2];
  if (Status s = detail::compile_per_channel_count(
          context, "phlm", "PHLM_C",
          {gpu::glsl::storage(0, "src"), gpu::glsl::storage(1, "prev"), gpu::glsl::storage(2, "nxt"),
           gpu::glsl::storage(3, "outb"), gpu::glsl::ycgco_box(), gpu::glsl::std_min_max(), kPhlmDecl,
           gpu::glsl::reproject(), kPhlmMain},
          programs);
      !s)
    return s.error();
  auto counters = gpu::ImageBuffer::create(context, 4, 1, 1);
  if (!counters) return counters.error();
  auto filter = std::make_unique<PhlmFilterGpu>(std::move(context), std::move(params), programs, std::move(*counters));
  filter->fetch_ = *fetch;
  return std::unique_ptr<FrameFilter>(std::move(filter));
}

}  // namespace temporal::phlm
