// `temporal` (temporal.cpp, seed 000 eq. 4 with the binary weight) as one GLSL compute kernel: the new sample where
// this frame shaded the pixel, else the previous output at p + motion through the gpu stage's GLSL reprojection
// (warped depth and ids as history_row sets them up), the joint-bilateral result in the holes. Same state planes
// (history.<c>, prev.depth, prev.id).
#include "gpu_methods.h"
#include "temporal/gpu/glsl.h"
#include "temporal/gpu/timer.h"

namespace temporal::upsample {
namespace {

// Buffers: gb (0) and lowb (1) as GpuFrame; outb (2) this frame's output C planes, then debug.disocclusion and
// debug.confidence; hist (3) the previous output; prevg (4) the previous frame's depth (plane 0) and ids (1).
constexpr const char* kTemporalDecl = R"(
uniform bool u_history, u_use_ids, u_warped, u_debug;
uniform float u_tol, u_warped_tol;
#define REPROJECT_PREV_Z(q) prevg[uint(q)]
#define REPROJECT_PREV_ID(q) prevg_u[u_n + uint(q)]
)";

constexpr const char* kTemporalMain = R"(
void main() {
  ivec2 p;
  uint i;
  const bool inside = pixel_index(p, i);
  count_begin();
  if (inside) {
    const JB j = jb_weights(p);
    // w_t of eq. 4: 1 where this frame shaded the pixel and its sample is finite.
    const bool computed = j.computed && j.valid0;
    bool hit = false;
    Taps t;
    if (u_history) {
      t = reproject_taps(p, vec2(gb[4u * u_n + i], gb[5u * u_n + i]));
      const float z = expect_depth(gb[i], gb[6u * u_n + i], u_warped);
      hit = reproject_test(t, z, gb_u[7u * u_n + i], true, u_use_ids, expect_tolerance(u_tol, u_warped_tol, u_warped));
    }
    const bool hole = !computed && !hit;
    for (int c = 0; c < u_C; ++c) {
      float v;
      if (computed)
        v = lowb[uint(c) * u_ln + j.q[0]];  // eq. 4, w_t = 1
      else if (hit)
        v = REPROJECT_GATHER(hist, uint(c) * u_n, t);  // w_t = 0: the previous output at p + motion
      else
        v = jb_value(j, c);  // a hole: the joint-bilateral result
      outb[uint(c) * u_n + i] = v;
    }
    if (u_debug) {
      outb[uint(u_C) * u_n + i] = hole ? 1.0 : 0.0;
      outb[uint(u_C + 1) * u_n + i] = jb_sum(j);
    }
    count_add(0, hole);
    count_add(1, !computed && hit);
  }
  count_end();
}
)";

class TemporalStateGpu final : public GpuHistoryState {
 public:
  TemporalStateGpu(std::shared_ptr<gpu::Context> ctx, gpu::Program program, gpu::ImageBuffer counters,
                   const Geometry& g)
      : GpuHistoryState(std::move(ctx), std::move(counters), g), program_(std::move(program)) {}

  void save(Image& state) const override {
    if (!allocate_const_ok()) return;
    save_history(state);
    save_previous_geometry(prevg_, has_prev_id_, g_, state);
  }

  Status load(const Image& state) override {
    if (Status s = allocate(); !s) return s;
    cur_ = 1 - cur_;  // as OutputPair::next(): the loaded history is the previous output of the next run()
    if (Status s = load_history(state); !s) return s;
    return upload_previous_geometry(state, g_, prevg_, has_prev_id_);
  }

 private:
  bool allocate_const_ok() const { return !out_[0].empty() && !prevg_.empty(); }

  Status allocate() {
    if (allocate_const_ok()) return Status::ok();
    const int planes = int(g_.channels.size()) + 2;
    return gpu::ImageBuffer::create_all(
        ctx_, {{&out_[0], g_.W, g_.H, planes}, {&out_[1], g_.W, g_.H, planes}, {&prevg_, g_.W, g_.H, 2}});
  }

  Status run_gpu(const FrameContext& f, bool history, FrameStats& stats) override {
    if (Status s = allocate(); !s) return s;
    if (Status s = frame_.upload(ctx_, f, true); !s) return s;
    if (Status s = counters_.clear(0, 1); !s) return s;
    cur_ = 1 - cur_;  // OutputPair::next()
    const Options& o = *f.options;
    const reproject::SurfaceTest test = o.surface_test();
    // history_row: ids compared when the options ask for them and both frames have them.
    const bool use_ids = test.use_ids && f.id && has_prev_id_;
    if (Status s = program_.use(); !s) return s;
    set_joint_bilateral_uniforms(program_, f);
    program_.set("u_history", int(history));
    program_.set("u_use_ids", int(use_ids));
    program_.set("u_warped", int(f.prev_z != nullptr));
    program_.set("u_debug", int(f.debug));
    program_.set("u_tol", test.depth_tolerance);
    program_.set("u_warped_tol", o.warped_depth_tolerance);
    bind_history_buffers();
    counters_.bind(15);
    timer_.start();
    if (Status s = program_.dispatch(f.W, f.H); !s) return s;
    timing_.kernel_ms = timer_.stop_ms();
    timing_.clock = timer_.clock();
    // temporal.cpp's streamed_bytes (+ the debug planes).
    const double full = double(f.W) * f.H * 4.0, low = double(f.lw) * f.lh * 4.0;
    timing_.bytes_moved = 4.0 * full + f.C * low + f.C * full + 2 * full + full + 2 * (2 * full) + f.C * full +
                          (f.debug ? 2.0 * full : 0.0);

    static const char* const kDebugNames[2] = {"debug.disocclusion", "debug.confidence"};
    if (Status s = download_result(f, kDebugNames); !s) return s;
    if (Status s = store_previous_geometry(f); !s) return s;
    std::uint32_t counts[4] = {};
    if (Status s = counters_.download(0, counts); !s) return s;
    stats.hole_pixels = counts[0];
    stats.history_pixels = counts[1];
    return Status::ok();
  }

  gpu::Program program_;
};

}  // namespace

Expected<std::unique_ptr<MethodState>> make_temporal_state_gpu(std::shared_ptr<gpu::Context> context,
                                                               const Options&, const Geometry& geometry) {
  if (Status s = gpu::Context::ensure(context); !s) return s.error();
  auto program = gpu::Program::compile(
      context, "temporal",
      {gpu::glsl::prelude(), gpu::glsl::storage(0, "gb"), gpu::glsl::storage(1, "lowb"),
       gpu::glsl::storage(2, "outb"), gpu::glsl::storage(3, "hist"), gpu::glsl::storage(4, "prevg"),
       joint_bilateral_glsl(),
       kTemporalDecl, gpu::glsl::reproject(), kTemporalMain});
  if (!program) return program.error();
  auto counters = gpu::ImageBuffer::create(context, 4, 1, 1);
  if (!counters) return counters.error();
  return std::unique_ptr<MethodState>(
      new TemporalStateGpu(std::move(context), std::move(*program), std::move(*counters), geometry));
}

}  // namespace temporal::upsample
