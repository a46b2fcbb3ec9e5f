// The EMA filter (ema.cpp) as one GLSL compute kernel: the same reprojection (the gpu stage's GLSL version of
// core/reproject.h), the same eq. 1, the same state planes (history.<c>, history.depth, history.id).
#include "gpu_history.h"
#include "temporal/phlm/gpu_filters.h"

#include <algorithm>

namespace temporal::phlm {
namespace {

// Buffers: `src` (binding 0) the frame: colour planes 0..C-1, then motion.X, motion.Y, depth, the warped depth,
// id; `hist` (1) the history: colour 0..C-1, depth C, id C+1; `nxt` (2) the next history, same layout plus the
// debug plane C+2. Plane p of a buffer starts at p * u_n.
constexpr const char* kEmaKernel = R"(
uniform uint u_n;
uniform int u_channels;
uniform bool u_motion, u_reject_all, u_use_depth, u_use_ids, u_warped, u_write_depth, u_write_id, u_debug;
uniform float u_alpha, u_tol, u_warped_tol;

#define SRC(p) (uint(p) * u_n)
#define REPROJECT_PREV_Z(q) hist[SRC(u_channels) + uint(q)]
#define REPROJECT_PREV_ID(q) hist_u[SRC(u_channels + 1) + uint(q)]
)";

constexpr const char* kEmaMain = R"(
void main() {
  ivec2 p;
  uint i;
  const bool inside = pixel_index(p, i);
  count_begin();
  if (inside) {
    const int C = u_channels;
    const uint mx = SRC(C), my = SRC(C + 1), depth = SRC(C + 2), warped = SRC(C + 3), id = SRC(C + 4);
    bool valid = true;
    float y[3];
    for (int c = 0; c < C; ++c) {
      y[c] = src[SRC(c) + i];
      valid = valid && is_sample(y[c]);
    }
    // ema.cpp: reject = reset || no history of this size || the shared reprojection misses.
    bool reject = u_reject_all;
    Taps t;
    if (!reject) {
      t = reproject_taps(p, u_motion ? vec2(src[mx + i], src[my + i]) : vec2(0.0));
      const float z = u_use_depth ? expect_depth(src[depth + i], src[warped + i], u_warped) : 0.0;
      const float tol = expect_tolerance(u_tol, u_warped_tol, u_warped);
      reject = !reproject_test(t, z, u_use_ids ? src_u[id + i] : 0u, u_use_depth, u_use_ids, tol);
    }
    for (int c = 0; c < C; ++c) {
      const float hv = reject ? 0.0 : REPROJECT_GATHER(hist, SRC(c), t);
      float v;
      if (valid)
        v = reject ? y[c] : u_alpha * hv + (1.0 - u_alpha) * y[c];  // eq. 1
      else
        v = hv;  // no valid sample: keep the history (0 when there is none)
      nxt[SRC(c) + i] = v;
    }
    if (u_write_depth) nxt[SRC(C) + i] = src[depth + i];
    if (u_write_id) nxt_u[SRC(C + 1) + i] = src_u[id + i];
    if (u_debug) nxt[SRC(C + 2) + i] = reject ? 1.0 : 0.0;
    count_add(0, !valid);
    count_add(1, reject);
  }
  count_end();
}
)";

class EmaFilterGpu final : public detail::HistoryGpuFilter {
 public:
  // src_: the colour planes, motion, depth, the warped depth and id (5 more); hist_ / next_: the history planes,
  // history.depth, history.id and next_'s debug plane (3 more).
  EmaFilterGpu(std::shared_ptr<gpu::Context> ctx, EmaParams params, gpu::Program program, gpu::ImageBuffer counters)
      : HistoryGpuFilter(std::move(ctx), std::move(counters), 5, 3), params_(params), program_(std::move(program)) {}

  Status process(const FilterInput& in, Image& output, FilterStats* stats) override {
    if (Status s = validate_filter_input(in); !s) return s;
    const int channels = int(in.channels.size());
    const int w = in.color->width(), h = in.color->height();
    const bool same = continues_history(channels, w, h);
    if (!same) {
      if (Status s = allocate(channels, w, h); !s) return s;
      has_depth_ = has_id_ = false;  // a fresh history (detail::allocate_history) has no G-buffer planes
    }
    const int C = channels;
    if (Status s = upload_colour(in, src_, true); !s) return s;
    if (in.depth)
      if (Status s = src_.upload(C + 2, in.depth); !s) return s;
    if (in.prev_depth)
      if (Status s = src_.upload(C + 3, in.prev_depth); !s) return s;
    if (in.id)
      if (Status s = src_.upload(C + 4, in.id); !s) return s;
    if (Status s = counters_.clear(0, 1); !s) return s;
    const bool use_depth = in.depth && has_depth_ && same;
    const bool use_id = in.id && has_id_ && same;

    if (Status s = program_.use(); !s) return s;
    program_.set("u_n", std::uint32_t(src_.pixel_count()));
    program_.set("u_channels", C);
    program_.set("u_motion", int(in.motion_x != nullptr));
    program_.set("u_reject_all", int(in.reset || !same));
    program_.set("u_use_depth", int(use_depth));
    program_.set("u_use_ids", int(use_id));
    program_.set("u_warped", int(use_depth && in.prev_depth != nullptr));
    program_.set("u_write_depth", int(in.depth != nullptr));
    program_.set("u_write_id", int(in.id != nullptr));
    program_.set("u_debug", int(in.debug));
    program_.set("u_alpha", params_.alpha);
    program_.set("u_tol", params_.depth_tolerance);
    program_.set("u_warped_tol", params_.warped_depth_tolerance);
    src_.bind(0);
    hist_.bind(1);
    next_.bind(2);
    if (Status s = timed([&] { return program_.dispatch(w, h); }); !s) return s;
    // Each plane read or written once: colour in and out, motion, depth (+ warped), id, the history planes read.
    const double plane = double(src_.pixel_count()) * 4.0;
    double planes = 2.0 * C + (in.motion_x ? 2 : 0) + (in.depth ? 2 : 0) + (in.prev_depth && use_depth ? 1 : 0) +
                    (in.id ? 2 : 0) + (same ? C : 0) + (use_depth ? 1 : 0) + (use_id ? 1 : 0) + (in.debug ? 1 : 0);
    timing_.bytes_moved = planes * plane;

    static const char* const kDebugNames[1] = {"debug.reject"};
    if (Status s = download_output(in, output, next_, C + 2, kDebugNames); !s) return s;
    std::swap(hist_, next_);
    has_depth_ = in.depth != nullptr;
    has_id_ = in.id != nullptr;
    have_state_ = true;
    if (stats) {
      std::uint32_t counts[4] = {};
      if (Status s = counters_.download(0, counts); !s) return s;
      *stats = {};
      stats->non_finite = counts[0];
      stats->history_resets = counts[1];
    }
    return Status::ok();
  }

  Image saved_state() const override {
    if (!have_state_) return {};
    Image state = detail::download_history(hist_, channels_);
    if (has_depth_) (void)hist_.download(channels_, state, "history.depth");
    if (has_id_) (void)hist_.download(channels_ + 1, state, "history.id", true);
    return state;
  }

  Status set_state(const Image& state, int channels) override {
    if (Status s = restore_history(state, channels, "ema"); !s) return s;
    has_depth_ = state.plane("history.depth") != nullptr;
    has_id_ = state.uint_plane("history.id") != nullptr;
    if (has_depth_)
      if (Status s = hist_.upload(channels, state, "history.depth"); !s) return s;
    if (has_id_)
      if (Status s = hist_.upload(channels + 1, state, "history.id"); !s) return s;
    have_state_ = true;
    return Status::ok();
  }

 private:
  EmaParams params_;
  gpu::Program program_;
  bool has_depth_ = false, has_id_ = false;
};

}  // namespace

Expected<std::unique_ptr<FrameFilter>> make_ema_filter_gpu(std::shared_ptr<gpu::Context> context, EmaParams params) {
  if (Status s = gpu::Context::ensure(context); !s) return s.error();
  auto program = gpu::Program::compile(
      context, "ema", {gpu::glsl::prelude(), gpu::glsl::storage(0, "src"), gpu::glsl::storage(1, "hist"),
                       gpu::glsl::storage(2, "nxt"), kEmaKernel, gpu::glsl::reproject(), kEmaMain});
  if (!program) return program.error();
  auto counters = gpu::ImageBuffer::create(context, 4, 1, 1);
  if (!counters) return counters.error();
  return std::unique_ptr<FrameFilter>(
      new EmaFilterGpu(std::move(context), params, std::move(*program), std::move(*counters)));
}

}  // namespace temporal::phlm
