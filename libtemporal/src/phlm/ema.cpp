// Exponential history buffer, seed 003 eq. 1, with reprojection and depth / id rejection.
#include "temporal/phlm/ema.h"

#include "filter_common.h"
#include "temporal/phlm/filters.h"
#include "temporal/phlm/gpu_filters.h"
#include "temporal/core/isa.h"
#include "temporal/core/parallel.h"
#include "temporal/core/reproject.h"

#include <algorithm>
#include <atomic>
#include <cmath>

namespace temporal::phlm {
namespace {

// What ema's rows read and write in one frame.
struct EmaFrame {
  const FilterInput* in;
  const reproject::Frames* frames;
  bool same;  // a history of this shape exists
  int w, channels;
  float alpha;
  const float* const* hist;
  const float* const* y;
  float* const* out;
  float* const* next;
  const std::uint8_t* valid;
  float* next_depth;
  std::uint32_t* next_id;
  float* dbg;
};

// The row copies, one per instruction set (temporal/core/isa.h); v3 and v4 contract eq. 1's alpha h + (1 - alpha) y
// into an FMA (v2 has none): v2 differs in the last bit (tests/core/isa_test.cpp); v3 and v4 are bit-identical.
#define TEMPORAL_ISA_FILE "ema_kernels.inc"
#include "temporal/core/isa_copies.inc"

std::size_t ema_rows_copy(const EmaFrame& e) { TEMPORAL_ISA_CALL(copy, return copy::ema_rows(e)) }

}  // namespace

EmaFilter::EmaFilter(EmaParams params) : params_(params) {}

std::vector<std::string> EmaFilter::state_channel_names(int channels) {
  return detail::history_channel_names(channels);
}

Status EmaFilter::process(const FilterInput& in, Image& output, FilterStats* stats) {
  if (Status s = validate_filter_input(in); !s) return s;
  const int channels = int(in.channels.size());
  const int w = in.color->width(), h = in.color->height();
  const bool same = have_state_ && channels == channels_ && history_.width() == w && history_.height() == h;
  if (!same) {
    channels_ = channels;
    detail::allocate_history(history_, next_, channels, w, h);
  }
  // The previous G-buffer planes are part of the state (so --state-in resumes the rejection too).
  if (in.depth) next_.add_channel("history.depth");
  if (in.id) next_.add_uint_channel("history.id");
  const std::size_t non_finite = detail::prepare_frame(in, false, nullptr, valid_);
  float* out[3] = {};
  detail::prepare_output(in, output, out);
  float* dbg = in.debug ? output.add_channel("debug.reject") : nullptr;

  const auto names = state_channel_names(channels);
  const float* hist[3] = {};
  float* next[3] = {};
  const float* y[3] = {};
  for (int c = 0; c < channels; ++c) {
    hist[c] = history_.plane(names[std::size_t(c)]);
    next[c] = next_.plane(names[std::size_t(c)]);
    y[c] = in.color->plane(in.channels[std::size_t(c)]);
  }
  const float* prev_depth = history_.plane("history.depth");
  const std::uint32_t* prev_id = history_.uint_plane("history.id");
  float* next_depth = in.depth ? next_.plane("history.depth") : nullptr;
  std::uint32_t* next_id = in.id ? next_.uint_plane("history.id") : nullptr;
  const bool use_depth = in.depth && prev_depth && same;
  const bool use_id = in.id && prev_id && same;
  const float alpha = params_.alpha, tol = params_.depth_tolerance;
  const std::uint8_t* valid = valid_.data();

  // The history fetch and its rejection are the shared reprojection rules (temporal/core/reproject.h): off
  // screen, or every bilinear tap another surface (depth and id of the previous frame) -> no history.
  reproject::Frames frames;
  frames.width = w;
  frames.height = h;
  frames.motion_x = in.motion_x;
  frames.motion_y = in.motion_y;
  frames.prev_z = use_depth ? prev_depth : nullptr;
  frames.id = use_id ? in.id : nullptr;
  frames.prev_id = use_id ? prev_id : nullptr;
  frames.test = {tol, use_id};
  // The expected previous depth: the warped depth when the G-buffer has it, else the current depth.
  if (use_depth) reproject::expect_depth(frames, in.depth, in.prev_depth, params_.warped_depth_tolerance);
  const EmaFrame frame{&in, &frames, same, w, channels, alpha, hist, y, out, next, valid, next_depth, next_id, dbg};
  const std::size_t rejected = ema_rows_copy(frame);
  std::swap(history_, next_);
  have_state_ = true;
  if (stats) {
    *stats = {};
    stats->non_finite = non_finite;
    stats->history_resets = rejected;
  }
  return Status::ok();
}

Status EmaFilter::set_state(const Image& state, int channels) {
  if (Status s = detail::load_history(state, channels, "ema", history_, next_); !s) return s;
  // The previous G-buffer planes travel with the state (so a resumed run rejects history the same way).
  if (const float* d = state.plane("history.depth"))
    std::copy(d, d + state.pixel_count(), history_.add_channel("history.depth"));
  if (const std::uint32_t* id = state.uint_plane("history.id"))
    std::copy(id, id + state.pixel_count(), history_.add_uint_channel("history.id"));
  channels_ = channels;
  have_state_ = true;
  return Status::ok();
}

// --- Registry entry (temporal/phlm/filters.h) ------------------------------------------------------------------

namespace {

// ema's parameters on the command line: the fields of EmaParams (ema.h).
struct EmaOptions : EmaParams {
  ParamList params() {
    return {
        Param::real("--ema-alpha", "history weight alpha of seed 003 eq. 1", &alpha, 0.0, 1.0),
        Param::positive("--ema-depth-tolerance",
                        "relative depth difference of the disocclusion test (temporal/core/reproject.h)",
                        &depth_tolerance, 0.0, 10.0),
        Param::positive("--ema-warped-depth-tolerance",
                        "the same when the G-buffer has prevDepth.Z (the warped depth, temporal/core/reproject.h)",
                        &warped_depth_tolerance, 0.0, 10.0),
    };
  }
};

}  // namespace

const MethodEntry& ema_method() {
  static const MethodEntry entry{
      .info = {.name = "ema",
               .summary = "weak reference: the exponential history of seed 003 eq. 1, disocclusion by depth and id",
               .has_state = true},
      .make_options = OptionsOf<EmaOptions>::make,
      .layers =
          [](const FilterOptions&) {
            return std::vector<LayerNeed>{{"motion"}, {"depth"}, {"id"}, {"prevDepth", false}};
          },
      .implementations = {{kCpuDevice, [](const FilterOptions& o) -> std::unique_ptr<FrameFilter> {
                             return std::make_unique<EmaFilter>(method_options<EmaOptions>(o.per_method, "ema"));
                           }},
                          {kGpuDevice,
                           [](std::shared_ptr<gpu::Context> c,
                              const FilterOptions& o) -> Expected<std::unique_ptr<FrameFilter>> {
                             return make_ema_filter_gpu(std::move(c), method_options<EmaOptions>(o.per_method, "ema"));
                           }}},
  };
  return entry;
}

}  // namespace temporal::phlm
