// TAA (taa.cpp, Karis 2014 with Salvi 2016's variance clipping) as one GLSL compute kernel per frame: the same
// steps in the same order (3x3 reconstruction filter, closest-depth velocity, Catmull-Rom / bilinear / nearest
// history through the gpu stage's GLSL reprojection, clipping in YCgCo, luminance-weighted blend), the same state
// (history.<c>). The reconstruction weights exp(-k d^2) are computed on the host with std::exp as in taa.cpp, so
// no GPU exp enters the result.
#include "gpu_history.h"
#include "temporal/phlm/gpu_filters.h"

#include <cmath>

namespace temporal::phlm {
namespace {

// Buffers: `src` (binding 0): colour planes 0..C-1, motion.X C, motion.Y C+1, depth C+2; `hist` (1): history
// planes 0..C-1; `nxt` (2): the next history 0..C-1, then debug.clip, debug.noHistory, debug.velocity.X/Y.
// C is a compile-time constant (TAA_C) so that the per-channel arrays stay in registers.
constexpr const char* kTaaKernel = R"(
uniform uint u_n;
uniform bool u_motion, u_dilate, u_no_history, u_variance, u_debug;
uniform int u_fetch;  // 0 Catmull-Rom, 1 bilinear, 2 nearest
uniform float u_alpha, u_gamma;
uniform float u_weight[9];
#define PLANE(p) (uint(p) * u_n)
)";

constexpr const char* kTaaMain = R"(
void main() {
  ivec2 p;
  uint i;
  const bool inside = pixel_index(p, i);
  count_begin();
  if (inside) {
    const int W = u_size.x, H = u_size.y;
    const int xx = p.x, yy = p.y;
    const int rows[3] = int[3](max(yy - 1, 0), yy, min(yy + 1, H - 1));
    const int cols[3] = int[3](max(xx - 1, 0), xx, min(xx + 1, W - 1));
    const float inf = uintBitsToFloat(0x7f800000u);
    float bmin[TAA_C], bmax[TAA_C], cur[TAA_C], m1[TAA_C];
    float samples[9 * TAA_C];
    for (int c = 0; c < TAA_C; ++c) {
      bmin[c] = inf;
      bmax[c] = -inf;
      cur[c] = 0.0;
      m1[c] = 0.0;
    }
    float wsum = 0.0;
    int count = 0;
    bool centre_valid = true;
    for (int j = 0; j < 3; ++j)
      for (int k = 0; k < 3; ++k) {
        const uint n = uint(rows[j]) * uint(W) + uint(cols[k]);
        float v[TAA_C];
        bool valid = true;
        for (int c = 0; c < TAA_C; ++c) {
          v[c] = src[PLANE(c) + n];
          valid = valid && is_sample(v[c]);
        }
        if (j == 1 && k == 1) centre_valid = valid;
        if (!valid) continue;
        const float wt = u_weight[j * 3 + k];
        wsum += wt;
        float b[TAA_C];
        to_box(v, b);
        for (int c = 0; c < TAA_C; ++c) {
          bmin[c] = min_(bmin[c], b[c]);
          bmax[c] = max_(bmax[c], b[c]);
          m1[c] += b[c];
          samples[count * TAA_C + c] = b[c];
          cur[c] += wt * v[c];
        }
        ++count;
      }
    const bool any_valid = wsum > 0.0;
    for (int c = 0; c < TAA_C; ++c) cur[c] = any_valid ? cur[c] / wsum : 0.0;

    // Velocity: the pixel's own motion, or that of the closest surface of the 3x3 neighbourhood (centre first,
    // then raster order; non-finite depths never win).
    uint vi = i;
    if (u_dilate) {
      const uint depth = PLANE(TAA_C + 2);
      float bz = is_finite_bits(src[depth + i]) ? src[depth + i] : inf;
      for (int j = max(yy - 1, 0); j <= min(yy + 1, H - 1); ++j)
        for (int k = max(xx - 1, 0); k <= min(xx + 1, W - 1); ++k) {
          const uint n = uint(j) * uint(W) + uint(k);
          if (src[depth + n] < bz) {
            bz = src[depth + n];
            vi = n;
          }
        }
    }
    const float mvx = u_motion ? src[PLANE(TAA_C) + vi] : 0.0;
    const float mvy = u_motion ? src[PLANE(TAA_C + 1) + vi] : 0.0;
    const vec2 f = vec2(float(xx) + mvx, float(yy) + mvy);
    const bool no_history = u_no_history || !reproject_on_screen(f);
    float result[TAA_C];
    float clipped = 0.0;
    if (no_history) {
      for (int c = 0; c < TAA_C; ++c) result[c] = cur[c];
    } else {
      float hv[TAA_C];
      if (u_fetch == 0) {
        const CatmullRom cr = catmull_rom(f);
        for (int c = 0; c < TAA_C; ++c) CATMULL_ROM_FETCH(hv[c], hist, PLANE(c), cr)
      } else if (u_fetch == 1) {
        const Taps bl = reproject_bilinear(f);
        for (int c = 0; c < TAA_C; ++c) hv[c] = REPROJECT_GATHER(hist, PLANE(c), bl);
      } else {
        const uint q = uint(reproject_nearest(f));
        for (int c = 0; c < TAA_C; ++c) hv[c] = hist[PLANE(c) + q];
      }
      if (!any_valid) {
        for (int c = 0; c < TAA_C; ++c) result[c] = hv[c];  // nothing valid to blend in: keep the history
      } else {
        float hb[TAA_C], cb[TAA_C], origin[TAA_C];
        to_box(hv, hb);
        to_box(cur, cb);
        if (u_variance) {
          const float inv_n = 1.0 / float(count);
          for (int c = 0; c < TAA_C; ++c) {
            const float mu = m1[c] * inv_n;
            float m2 = 0.0;
            for (int k = 0; k < count; ++k)
              m2 += (samples[k * TAA_C + c] - mu) * (samples[k * TAA_C + c] - mu);
            const float sigma = sqrt(m2 * inv_n);
            bmin[c] = mu - u_gamma * sigma;
            bmax[c] = mu + u_gamma * sigma;
            origin[c] = mu;
          }
        } else {
          for (int c = 0; c < TAA_C; ++c) origin[c] = cb[c];
        }
        float t = 1.0;
        for (int c = 0; c < TAA_C; ++c) {
          const float d = hb[c] - origin[c];
          if (d > 0.0 && origin[c] + d > bmax[c]) t = min_(t, max_(bmax[c] - origin[c], 0.0) / d);
          if (d < 0.0 && origin[c] + d < bmin[c]) t = min_(t, min_(bmin[c] - origin[c], 0.0) / d);
        }
        if (t < 1.0) {
          for (int c = 0; c < TAA_C; ++c) hb[c] = origin[c] + t * (hb[c] - origin[c]);
          from_box(hb, hv);
          clipped = 1.0;
        }
        const float lc = max_(cb[0], 0.0), lh = max_(hb[0], 0.0);
        const float wc = u_alpha / (1.0 + lc), wh = (1.0 - u_alpha) / (1.0 + lh);
        const float inv = 1.0 / (wc + wh);
        for (int c = 0; c < TAA_C; ++c) result[c] = (wc * cur[c] + wh * hv[c]) * inv;
      }
    }
    for (int c = 0; c < TAA_C; ++c) nxt[PLANE(c) + i] = result[c];
    if (u_debug) {
      nxt[PLANE(TAA_C) + i] = clipped;
      nxt[PLANE(TAA_C + 1) + i] = no_history ? 1.0 : 0.0;
      nxt[PLANE(TAA_C + 2) + i] = mvx;
      nxt[PLANE(TAA_C + 3) + i] = mvy;
    }
    count_add(0, no_history);
    count_add(1, clipped > 0.0);
    count_add(2, !centre_valid);
  }
  count_end();
}
)";

class TaaFilterGpu final : public detail::HistoryGpuFilter {
 public:
  // src_: the colour planes, motion and depth (3 more); hist_ / next_: the history planes and next_'s four debug
  // planes (4 more).
  TaaFilterGpu(std::shared_ptr<gpu::Context> ctx, TaaParams params, detail::TaaConfig cfg, gpu::Program programs[2],
               gpu::ImageBuffer counters)
      : HistoryGpuFilter(std::move(ctx), std::move(counters), 3, 4), params_(std::move(params)), cfg_(cfg) {
    programs_[0] = std::move(programs[0]);
    programs_[1] = std::move(programs[1]);
  }

  Status process(const FilterInput& in, Image& output, FilterStats* stats) override {
    if (Status s = validate_filter_input(in); !s) return s;
    if (Status s = detail::check_taa_input(cfg_, in); !s) return s;
    const int C = int(in.channels.size());
    const int w = in.color->width(), h = in.color->height();
    const bool same = continues_history(C, w, h);
    if (!same)
      if (Status s = allocate(C, w, h); !s) return s;
    if (Status s = upload_colour(in, src_, true); !s) return s;
    const bool dilate = cfg_.velocity == TaaVelocity::Nearest && in.motion_x && in.depth;
    if (dilate)
      if (Status s = src_.upload(C + 2, in.depth); !s) return s;
    if (Status s = counters_.clear(0, 1); !s) return s;

    // taa.cpp's reconstruction weights, on the host with the same std::exp.
    float weight[9];
    for (int j = 0; j < 3; ++j)
      for (int k = 0; k < 3; ++k) {
        const float dx = float(k - 1) + in.jitter.x, dy = float(j - 1) + in.jitter.y;
        weight[j * 3 + k] = std::exp(-params_.filter_sharpness * (dx * dx + dy * dy));
      }
    const gpu::Program& program = programs_[C == 3 ? 1 : 0];
    if (Status s = program.use(); !s) return s;
    program.set("u_n", std::uint32_t(src_.pixel_count()));
    program.set("u_motion", int(in.motion_x != nullptr));
    program.set("u_dilate", int(dilate));
    program.set("u_no_history", int(in.reset || !same));
    program.set("u_variance", int(cfg_.clip == TaaClip::Variance));
    program.set("u_debug", int(in.debug));
    program.set("u_fetch",
                cfg_.history == HistoryFetch::CatmullRom ? 0 : cfg_.history == HistoryFetch::Bilinear ? 1 : 2);
    program.set("u_alpha", cfg_.alpha);
    program.set("u_gamma", cfg_.gamma);
    program.set("u_weight", weight, 9);
    src_.bind(0);
    hist_.bind(1);
    next_.bind(2);
    if (Status s = timed([&] { return program.dispatch(w, h); }); !s) return s;
    // Each plane read or written once: colour in, motion, depth, history in, result out (+ debug planes).
    const double plane = double(src_.pixel_count()) * 4.0;
    const double planes =
        C + (in.motion_x ? 2 : 0) + (dilate ? 1 : 0) + (same && !in.reset ? C : 0) + C + (in.debug ? 4 : 0);
    timing_.bytes_moved = planes * plane;

    static const char* const kDebugNames[4] = {"debug.clip", "debug.noHistory", "debug.velocity.X",
                                               "debug.velocity.Y"};
    if (Status s = download_output(in, output, next_, C, kDebugNames); !s) return s;
    std::swap(hist_, next_);
    have_state_ = true;
    if (stats) {
      std::uint32_t counts[4] = {};
      if (Status s = counters_.download(0, counts); !s) return s;
      *stats = {};
      stats->history_resets = counts[0];
      stats->clamped = counts[1];
      stats->non_finite = counts[2];
    }
    return Status::ok();
  }

  Image saved_state() const override {
    if (!have_state_) return {};
    return detail::download_history(hist_, channels_);
  }

  Status set_state(const Image& state, int channels) override {
    if (Status s = restore_history(state, channels, "taa"); !s) return s;
    have_state_ = true;
    return Status::ok();
  }

 private:
  TaaParams params_;
  detail::TaaConfig cfg_;
  gpu::Program programs_[2];  // 1 and 3 channels
};

}  // namespace

Expected<std::unique_ptr<FrameFilter>> make_taa_filter_gpu(std::shared_ptr<gpu::Context> context, TaaParams params) {
  auto cfg = detail::resolve_taa(params);
  if (!cfg) return cfg.error();
  if (Status s = gpu::Context::ensure(context); !s) return s.error();
  gpu::Program programs[2];
  if (Status s = detail::compile_per_channel_count(
          context, "taa", "TAA_C",
          {gpu::glsl::storage(0, "src"), gpu::glsl::storage(1, "hist"), gpu::glsl::storage(2, "nxt"),
           gpu::glsl::ycgco_box(), gpu::glsl::std_min_max(), kTaaKernel, gpu::glsl::reproject(),
           kTaaMain},
          programs);
      !s)
    return s.error();
  auto counters = gpu::ImageBuffer::create(context, 4, 1, 1);
  if (!counters) return counters.error();
  return std::unique_ptr<FrameFilter>(
      new TaaFilterGpu(std::move(context), std::move(params), *cfg, programs, std::move(*counters)));
}

}  // namespace temporal::phlm
