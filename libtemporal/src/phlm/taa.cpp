// TAA after Karis 2014 with Salvi 2016's variance clipping (the engine-strength baseline of seed 003 Table 2).
// The source of every choice is listed in docs/filter-phlm.md ("TAA").
#include "temporal/phlm/taa.h"

#include "filter_common.h"
#include "temporal/phlm/filters.h"
#include "temporal/phlm/gpu_filters.h"
#include "temporal/core/color.h"
#include "temporal/core/isa.h"
#include "temporal/core/minmax.h"
#include "temporal/core/parallel.h"
#include "temporal/core/reproject.h"

#include <algorithm>
#include <atomic>
#include <cfloat>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <type_traits>

namespace temporal::phlm {
namespace {

using detail::TaaConfig;

// The kernel copies, one per instruction set (temporal/core/isa.h). v3 and v4 contract the multiply-adds of the
// reconstruction filter, the history fetch and the blend into FMAs (v2 has none): v2's output differs from
// theirs in the last bits (tests/core/isa_test.cpp bounds that); v3 and v4 are bit-identical.
#define TEMPORAL_ISA_FILE "taa_kernels.inc"
#include "temporal/core/isa_copies.inc"

template <int C>
void run_taa_copy(const FilterInput& in, const TaaParams& params, const TaaConfig& cfg, bool have_history,
                  const float* const hist[C], float* const next[C], const float* const box[C],
                  const std::uint8_t* valid, float* const out[C], float* const dbg[4],
                  std::atomic<std::size_t>& resets, std::atomic<std::size_t>& clips) {
  TEMPORAL_ISA_CALL(copy, return copy::run_taa<C>(in, params, cfg, have_history, hist, next, box, valid, out, dbg,
                                                    resets, clips))
}

}  // namespace

Expected<TaaConfig> detail::resolve_taa(const TaaParams& p) {
  TaaConfig cfg;
  cfg.alpha = p.alpha;
  cfg.gamma = p.gamma;
  if (!(p.alpha >= 0.0f && p.alpha <= 1.0f)) return Error::usage("--taa-alpha must be in [0, 1]");
  if (!(p.gamma > 0.0f && std::isfinite(p.gamma))) return Error::usage("--taa-gamma must be a finite number > 0");
  if (p.velocity == "nearest")
    cfg.velocity = TaaVelocity::Nearest;
  else if (p.velocity == "centre")
    cfg.velocity = TaaVelocity::Centre;
  else
    return Error::usage("--taa-velocity '" + p.velocity + "' is not one of: nearest, centre");
  if (p.clip == "variance")
    cfg.clip = TaaClip::Variance;
  else if (p.clip == "minmax")
    cfg.clip = TaaClip::MinMax;
  else
    return Error::usage("--taa-clip '" + p.clip + "' is not one of: variance, minmax");
  auto fetch = parse_history_fetch(p.history, "--taa-history");
  if (!fetch) return fetch.error();
  cfg.history = *fetch;
  return cfg;
}

Status detail::check_taa_input(const TaaConfig& cfg, const FilterInput& in) {
  if (cfg.velocity == TaaVelocity::Nearest && in.motion_x && !in.depth)
    return Error::usage("taa: --taa-velocity nearest takes the motion of the closest surface and needs the "
                        "G-buffer's depth; render it (render-gbuffer --outputs gbuffer) or use --taa-velocity centre");
  return Status::ok();
}

TaaFilter::TaaFilter(TaaParams params) : params_(params) {}

std::vector<std::string> TaaFilter::state_channel_names(int channels) {
  return detail::history_channel_names(channels);
}

Status TaaFilter::process(const FilterInput& in, Image& output, FilterStats* stats) {
  if (Status s = validate_filter_input(in); !s) return s;
  const int channels = int(in.channels.size());
  const int w = in.color->width(), h = in.color->height();
  auto cfg = detail::resolve_taa(params_);
  if (!cfg) return cfg.error();
  if (Status s = detail::check_taa_input(*cfg, in); !s) return s;
  const bool same = have_state_ && channels == channels_ && history_.width() == w && history_.height() == h;
  if (!same) {
    channels_ = channels;
    detail::allocate_history(history_, next_, channels, w, h);
  }
  const std::size_t non_finite = detail::prepare_frame(in, channels == 3, ycgco_, valid_);
  float* out[3] = {};
  detail::prepare_output(in, output, out);
  float* dbg[4] = {};
  if (in.debug) {
    dbg[0] = output.add_channel("debug.clip");
    dbg[1] = output.add_channel("debug.noHistory");
    dbg[2] = output.add_channel("debug.velocity.X");
    dbg[3] = output.add_channel("debug.velocity.Y");
  }
  const auto names = state_channel_names(channels);
  const float* hist[3] = {};
  float* next[3] = {};
  const float* box[3] = {};
  for (int c = 0; c < channels; ++c) {
    hist[c] = history_.plane(names[std::size_t(c)]);
    next[c] = next_.plane(names[std::size_t(c)]);
    box[c] = channels == 3 ? ycgco_[c].data() : in.color->plane(in.channels[0]);
  }
  std::atomic<std::size_t> resets{0}, clips{0};
  if (channels == 3)
    run_taa_copy<3>(in, params_, *cfg, same, hist, next, box, valid_.data(), out, dbg, resets, clips);
  else
    run_taa_copy<1>(in, params_, *cfg, same, hist, next, box, valid_.data(), out, dbg, resets, clips);
  std::swap(history_, next_);
  have_state_ = true;
  if (stats) {
    *stats = {};
    stats->non_finite = non_finite;
    stats->history_resets = resets.load();
    stats->clamped = clips.load();
  }
  return Status::ok();
}

Status TaaFilter::set_state(const Image& state, int channels) {
  if (Status s = detail::load_history(state, channels, "taa", history_, next_); !s) return s;
  channels_ = channels;
  have_state_ = true;
  return Status::ok();
}

// --- Registry entry (temporal/phlm/filters.h) ------------------------------------------------------------------

namespace {

// taa's parameters on the command line: the fields of TaaParams (taa.h).
struct TaaOptions : TaaParams {
  ParamList params() {
    return {
        Param::real("--taa-alpha", "weight of the current frame (chosen on the tuning set, docs/filter-phlm.md)",
                    &alpha, 0.0, 1.0),
        Param::choice("--taa-velocity",
                      "motion of the closest surface of the 3x3 neighbourhood (nearest, UE4) or of the pixel",
                      &velocity, {"nearest", "centre"}),
        Param::choice("--taa-clip",
                      "history clipping in YCoCg to mu +- gamma sigma (variance, Salvi 2016) or to the 3x3 min/max "
                      "box (minmax, Karis 2014)",
                      &clip, {"variance", "minmax"}),
        Param::positive("--taa-gamma", "gamma of variance clipping (Salvi 2016: 1)", &gamma, 0.0, 8.0),
        Param::choice("--taa-history", "history fetch (Karis 2014: catmull-rom)", &history,
                      {"catmull-rom", "bilinear", "nearest"}),
    };
  }
};

}  // namespace

const MethodEntry& taa_method() {
  static const MethodEntry entry{
      .info = {.name = "taa",
               .summary = "engine-strength TAA: Karis 2014 with nearest-depth velocity, Catmull-Rom history, variance "
                          "clipping (Salvi 2016)",
               .has_state = true},
      .make_options = OptionsOf<TaaOptions>::make,
      .layers = [](const FilterOptions&) { return std::vector<LayerNeed>{{"motion"}, {"depth", false}}; },
      .implementations = {{kCpuDevice, [](const FilterOptions& o) -> std::unique_ptr<FrameFilter> {
                             return std::make_unique<TaaFilter>(method_options<TaaOptions>(o.per_method, "taa"));
                           }},
                          {kGpuDevice,
                           [](std::shared_ptr<gpu::Context> c,
                              const FilterOptions& o) -> Expected<std::unique_ptr<FrameFilter>> {
                             return make_taa_filter_gpu(std::move(c), method_options<TaaOptions>(o.per_method, "taa"));
                           }}},
  };
  return entry;
}

}  // namespace temporal::phlm
