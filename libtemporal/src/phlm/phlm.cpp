// Pixel History Linear Models, seed 003 sections 4-6 and Algorithm 1. The terms the paper leaves loose and
// how they are read here are listed in docs/filter-phlm.md ("Reading the paper").
// rls.h's steps are instantiated below for phlm_kernels.inc's vectors; the templates are compiled for the baseline
// target, where GCC notes that a 32-byte vector is returned under another ABI than with AVX. They are always inlined
// into the v3 / v4 kernels (no call, so no ABI), so the note does not apply.
#pragma GCC diagnostic ignored "-Wpsabi"

#include "temporal/phlm/phlm.h"

#include "filter_common.h"
#include "temporal/phlm/filters.h"
#include "temporal/phlm/gpu_filters.h"
#include "temporal/core/color.h"
#include "temporal/core/isa.h"
#include "temporal/core/minmax.h"
#include "temporal/core/parallel.h"
#include "temporal/core/reproject.h"
#include "temporal/phlm/rls.h"

#include <algorithm>
#include <array>
#include <atomic>
#include <cfloat>
#include <cstdint>
#include <cmath>
#include <cstring>
#include <type_traits>
#include <vector>

namespace temporal::phlm {
namespace {

// The resolved ablation switches of PhlmParams.
struct Variant {
  bool feature = true, box_test = true, alpha_eq1 = false, phi_linear = false;
  HistoryFetch fetch = HistoryFetch::Bilinear;
};

Expected<Variant> resolve_variant(const PhlmParams& p) {
  Variant v;
  v.feature = !p.no_feature;
  v.box_test = !p.no_box_test;
  if (p.alpha_reading == "eq1")
    v.alpha_eq1 = true;
  else if (p.alpha_reading != "ue4")
    return Error::usage("--feature-alpha '" + p.alpha_reading + "' is not one of: ue4, eq1");
  if (p.feature_phi == "linear")
    v.phi_linear = true;
  else if (p.feature_phi != "paper")
    return Error::usage("--feature-phi '" + p.feature_phi + "' is not one of: paper, linear");
  auto fetch = parse_history_fetch(p.model_fetch, "--model-fetch");
  if (!fetch) return fetch.error();
  v.fetch = *fetch;
  return v;
}

struct FrameScratch {
  const float* y[3];       // input planes
  const float* box[3];     // input in box space (YCgCo or the value)
  const std::uint8_t* valid;
};


// The kernel copies, one per instruction set (temporal/core/isa.h). v3 and v4 contract the multiply-adds of the
// bilinear model fetch, the RLS update and the predictions into FMAs (v2 has none): v2's outputs and states
// differ from theirs in the last bits, amplified by the RLS over frames (tests/core/isa_test.cpp bounds it). v3 and
// v4 run the same 8-lane vector code and give the same bits.
// phlm_kernels.inc runs Algorithm 1 for kLanes pixels at once, one per vector lane (lanes.inc: one SSE vector in
// the v2 copy, one AVX vector in v3 and v4; v4 stays at 256 bits: phlm_kernels.inc says why).
#define TEMPORAL_ISA_FILE "phlm_kernels.inc"
#include "temporal/core/isa_copies.inc"

template <int C>
void run_phlm_copy(const FilterInput& in, const PhlmParams& params, const Variant& variant, bool have_prev,
                   const float* prev, float* next, const FrameScratch& fs, float* const out[C],
                   float* const dbg[3 + C], std::atomic<std::size_t>& resets, std::atomic<std::size_t>& clamps,
                   float& max_trace) {
  TEMPORAL_ISA_CALL(copy, return copy::run_phlm<C>(in, params, variant, have_prev, prev, next, fs, out, dbg, resets,
                                                     clamps, max_trace))
}

}  // namespace

PhlmFilter::PhlmFilter(PhlmParams params) : params_(params) {}

std::vector<std::string> PhlmFilter::state_channel_names(int channels) {
  const int n = channels + 1;
  std::vector<std::string> names;
  for (int c = 0; c < channels; ++c)
    for (int k = 0; k < n; ++k) names.push_back("beta." + std::string(detail::channel_suffix(channels, c)) + std::to_string(k));
  for (int k = 0; k < n; ++k) names.push_back("P.D" + std::to_string(k));
  for (int i = 0; i < n; ++i)
    for (int j = i + 1; j < n; ++j) names.push_back("P.U" + std::to_string(i) + std::to_string(j));
  for (int c = 0; c < channels; ++c) names.push_back("feature." + std::string(detail::channel_suffix(channels, c)));
  names.push_back("scale.s");
  return names;
}

Status PhlmFilter::process(const FilterInput& in, Image& output, FilterStats* stats) {
  if (Status s = validate_filter_input(in); !s) return s;
  const auto variant = resolve_variant(params_);
  if (!variant) return variant.error();
  const int channels = int(in.channels.size());
  const int w = in.color->width(), h = in.color->height();
  const bool same_shape = have_state_ && channels == channels_ && width_ == w && height_ == h;
  if (!same_shape) {
    channels_ = channels;
    width_ = w;
    height_ = h;
    const std::size_t n = std::size_t(w) * std::size_t(h) * std::size_t(phlm_state_floats(channels));
    state_.assign(n, 0.0f);
    next_.assign(n, 0.0f);
  }
  const bool have_prev = same_shape;

  FrameScratch fs{};
  const std::size_t non_finite = detail::prepare_frame(in, channels == 3, ycgco_, valid_);
  for (int c = 0; c < channels; ++c) {
    fs.y[c] = in.color->plane(in.channels[std::size_t(c)]);
    fs.box[c] = channels == 3 ? ycgco_[std::size_t(c)].data() : fs.y[c];
  }
  fs.valid = valid_.data();

  float* out[3] = {};
  detail::prepare_output(in, output, out);
  float* dbg[6] = {};
  if (in.debug) {
    dbg[0] = output.add_channel("debug.alpha");
    dbg[1] = output.add_channel("debug.reset");
    dbg[2] = output.add_channel("debug.traceP");
    for (int c = 0; c < channels; ++c)
      dbg[3 + c] = output.add_channel(channels == 3 ? "debug.feature" + std::string(detail::channel_suffix(3, c))
                                                    : std::string("debug.feature"));
  }

  std::atomic<std::size_t> resets{0}, clamps{0};
  float max_trace = 0.0f;
  if (channels == 3) {
    run_phlm_copy<3>(in, params_, *variant, have_prev, state_.data(), next_.data(), fs, out, dbg, resets, clamps,
                     max_trace);
  } else {
    run_phlm_copy<1>(in, params_, *variant, have_prev, state_.data(), next_.data(), fs, out, dbg, resets, clamps,
                     max_trace);
  }
  std::swap(state_, next_);
  have_state_ = true;
  if (stats) {
    stats->non_finite = non_finite;
    stats->history_resets = resets.load();
    stats->clamped = clamps.load();
    stats->max_trace_p = max_trace;
  }
  return Status::ok();
}

Image PhlmFilter::state() const {
  if (!have_state_) return Image();
  Image img(width_, height_);
  const auto names = state_channel_names(channels_);
  std::vector<float*> planes;
  for (const auto& n : names) planes.push_back(img.add_channel(n));
  const std::size_t size = names.size();
  parallel_chunks(img.pixel_count(), [&](std::size_t b0, std::size_t b1) {
    for (std::size_t i = b0; i < b1; ++i)
      for (std::size_t k = 0; k < size; ++k) planes[k][i] = state_[i * size + k];
  });
  return img;
}

Image PhlmFilter::state_with_covariance() const {
  Image out = state();
  if (!have_state_) return out;
  const int n = channels_ + 1;
  const auto names = state_channel_names(channels_);
  const int off = n * (n - 1) / 2;
  const std::size_t d_first = std::size_t(channels_ * n);
  std::vector<const float*> d(static_cast<std::size_t>(n));
  std::vector<const float*> u(static_cast<std::size_t>(std::max(off, 1)));
  for (int k = 0; k < n; ++k) d[std::size_t(k)] = out.plane(names[d_first + std::size_t(k)]);
  for (int k = 0; k < off; ++k) u[std::size_t(k)] = out.plane(names[d_first + std::size_t(n + k)]);
  std::vector<float*> p;
  for (int i = 0; i < n; ++i)
    for (int j = i; j < n; ++j) p.push_back(out.add_channel("Pmat.P" + std::to_string(i) + std::to_string(j)));
  for (std::size_t i = 0; i < out.pixel_count(); ++i) {
    float uu[6] = {}, dd[4] = {}, pp[10] = {};
    for (int k = 0; k < n; ++k) dd[k] = d[std::size_t(k)][i];
    for (int k = 0; k < off; ++k) uu[k] = u[std::size_t(k)][i];
    if (n == 4)
      rls::covariance<4>(uu, dd, pp);
    else
      rls::covariance<2>(uu, dd, pp);
    for (std::size_t k = 0; k < p.size(); ++k) p[k][i] = pp[k];
  }
  return out;
}

Status PhlmFilter::set_state(const Image& state, int channels) {
  if (channels != 1 && channels != 3)
    return Error::usage("phlm state: the filtered layer must have 1 or 3 channels, not " + std::to_string(channels));
  const auto names = state_channel_names(channels);
  std::vector<const float*> planes;
  for (const auto& name : names) {
    const float* src = state.plane(name);
    if (!src)
      return Error::input({}, "state has no channel '" + name + "': write it with `filter-phlm --method phlm " +
                                  "--state-out` on the same --layer");
    if (count_non_finite({src, state.pixel_count()}) != 0)
      return Error::input({}, "state channel '" + name + "' holds NaN or Inf values; it cannot be resumed");
    // P = U D U^T must stay positive definite (D > 0) and the model scale s positive (model_scale gives s >= 1,
    // and bilinear fetches of it stay within rounding of that); anything else is not a state this filter wrote,
    // and would turn the next frame's update into NaN.
    const bool is_d = name.rfind("P.D", 0) == 0, is_scale = name == "scale.s";
    if (is_d || is_scale) {
      for (std::size_t i = 0; i < state.pixel_count(); ++i)
        if (!(src[i] > 0.0f))
          return Error::input({}, "state channel '" + name + "' holds " + std::to_string(src[i]) + " at pixel (" +
                                      std::to_string(i % std::size_t(state.width())) + ", " +
                                      std::to_string(i / std::size_t(state.width())) + "): " +
                                      (is_d ? "P must be positive definite" : "the model scale must be positive") +
                                      "; this is not a state written by filter-phlm --state-out");
    }
    planes.push_back(src);
  }
  channels_ = channels;
  width_ = state.width();
  height_ = state.height();
  const std::size_t size = names.size();
  state_.assign(state.pixel_count() * size, 0.0f);
  next_.assign(state.pixel_count() * size, 0.0f);
  for (std::size_t i = 0; i < state.pixel_count(); ++i)
    for (std::size_t k = 0; k < size; ++k) state_[i * size + k] = planes[k][i];
  have_state_ = true;
  return Status::ok();
}

std::string PhlmFilter::stats_text(const FilterStats& stats) const {
  return ", max trace(P) " + std::to_string(stats.max_trace_p);
}

// --- Registry entry (temporal/phlm/filters.h) ------------------------------------------------------------------

namespace {

// phlm's parameters on the command line: the fields of PhlmParams (phlm.h).
struct PhlmOptions : PhlmParams {
  ParamList params() {
    return {
        Param::real("--lambda", "RLS forgetting factor (seed 003 eq. 6-7)", &lambda, 0.5, 1.0),
        // Finite ranges (issue 26): trace_max = trace_factor * N * p_init and the gain P x / (lambda + x^T P x) of
        // eq. 6 stay finite and nonzero in float.
        Param::real("--p-init", "P = p_init * I at reset (seed 003 section 6)", &p_init, 1e-6, 1e6),
        Param::real("--feature-a", "a of phi(v,l) = a l^2 + b v l^3 (section 5.1)", &feature_a, -1e6, 1e6),
        Param::real("--feature-b", "b of phi(v,l)", &feature_b, -1e6, 1e6),
        Param::real("--trace-factor", "trace(P) <= factor * N * p_init (wind-up guard)", &trace_factor, 1e-3, 1e3),
        Param::flag_on("--no-feature",
                       "ablation: predictor x = [1], an intercept-only RLS (a per-pixel running mean with the same "
                       "resets)",
                       &no_feature),
        Param::flag_on("--no-box-test", "ablation: skip the box test and its resets (Algorithm 1 lines 13-19)",
                       &no_box_test),
        Param::choice("--feature-alpha",
                      "reading of the feature's alpha: ue4 = weight of the new sample, eq1 = history weight of eq. 1 "
                      "(ablation)",
                      &alpha_reading, {"ue4", "eq1"}),
        Param::choice("--feature-phi",
                      "phi of the feature's weight alpha = phi / (l + Delta): paper = a l^2 + b v l^3 (section 5.1 "
                      "as printed), linear = (a + b v) l (UE4's HistoryFactor; ablation)",
                      &feature_phi, {"paper", "linear"}),
        Param::choice("--model-fetch", "fetch of the previous models at p + motion (section 6: bilinear)",
                      &model_fetch, {"bilinear", "nearest", "catmull-rom"}),
    };
  }
};

}  // namespace

const MethodEntry& phlm_method() {
  static const MethodEntry entry{
      .info = {.name = "phlm", .summary = "pixel history linear models (seed 003)", .has_state = true},
      .make_options = OptionsOf<PhlmOptions>::make,
      .layers = [](const FilterOptions&) { return std::vector<LayerNeed>{{"motion"}}; },
      .implementations = {{kCpuDevice, [](const FilterOptions& o) -> std::unique_ptr<FrameFilter> {
                             return std::make_unique<PhlmFilter>(method_options<PhlmOptions>(o.per_method, "phlm"));
                           }},
                          {kGpuDevice,
                           [](std::shared_ptr<gpu::Context> c,
                              const FilterOptions& o) -> Expected<std::unique_ptr<FrameFilter>> {
                             return make_phlm_filter_gpu(std::move(c), method_options<PhlmOptions>(o.per_method, "phlm"));
                           }}},
  };
  return entry;
}

}  // namespace temporal::phlm
