// The GPU implementations of upsample-st's methods (GLSL compute kernels, temporal/gpu), not installed: each
// factory returns the same MethodState as the method's C++ entry (method.h) with the same state planes, so a run
// started on one device resumes on the other. The states also implement gpu::TimedKernel. Tolerances: docs/gpu.md.
#pragma once

#include "method.h"
#include "temporal/gpu/buffer.h"
#include "temporal/gpu/context.h"
#include "temporal/gpu/program.h"
#include "temporal/gpu/timer.h"

#include <memory>
#include <span>
#include <string_view>

namespace temporal::upsample {

// `spatial` (spatial.cpp): joint-bilateral upsampling, eq. 1-3 with the hat kernel.
Expected<std::unique_ptr<MethodState>> make_spatial_state_gpu(std::shared_ptr<gpu::Context> context,
                                                              const Options& options, const Geometry& geometry);
// `temporal` (temporal.cpp): eq. 4 with the binary weight, holes filled by the joint-bilateral result.
Expected<std::unique_ptr<MethodState>> make_temporal_state_gpu(std::shared_ptr<gpu::Context> context,
                                                               const Options& options, const Geometry& geometry);
// `herzog` (herzog.cpp): spatio-temporal upsampling, seed 000 sections 3.3-3.5, as its three passes (A: eq. 6 and
// the history fetch, B: the gradient's temporal filter, box pyramid and eq. 8, C: eq. 7), every option of
// HerzogOptions (herzog.h) included.
Expected<std::unique_ptr<MethodState>> make_herzog_state_gpu(std::shared_ptr<gpu::Context> context,
                                                             const Options& options, const Geometry& geometry);
// `taau` (taau.cpp): the FSR 2 / UE4 TAAU steps 1-5 per pixel, after a low-resolution pass for the thin features.
Expected<std::unique_ptr<MethodState>> make_taau_state_gpu(std::shared_ptr<gpu::Context> context,
                                                           const Options& options, const Geometry& geometry);
// `drobot` (drobot.cpp): seed 002's cache mode (cache grid, Listing 7.2 accumulation, Listing 7.3 filter, Listing 7.1
// upsampling) and the refresh mode of Figure 7.12, chosen by --mode when the state is made.
Expected<std::unique_ptr<MethodState>> make_drobot_state_gpu(std::shared_ptr<gpu::Context> context,
                                                             const Options& options, const Geometry& geometry);

// --- Registration as a method's "gpu" implementation (temporal/upsample/methods.h) ------------------------------

// The context the registered GPU implementations share: the one a live state already uses, else a new one on the
// default device (an error when EGL has none). Held by the states only, so it goes away with the last of them.
Expected<std::shared_ptr<gpu::Context>> shared_gpu_context();

// A StateFactory's result for a GPU factory's: the state, or (EGL or the kernel's compilation failed) a state that
// does nothing but return that error from load() and run_status(), which the Upsampler checks (a StateFactory
// cannot return an error itself).
std::unique_ptr<MethodState> state_or_failure(Expected<std::unique_ptr<MethodState>> made);

// `{kGpuDevice, gpu_implementation<make_X_state_gpu>}` in a method's `implementations`.
template <Expected<std::unique_ptr<MethodState>> (*Make)(std::shared_ptr<gpu::Context>, const Options&,
                                                         const Geometry&)>
std::unique_ptr<MethodState> gpu_implementation(const Options& options, const Geometry& geometry) {
  auto context = shared_gpu_context();
  if (!context) return state_or_failure(context.error());
  return state_or_failure(Make(std::move(*context), options, geometry));
}

// GLSL of the joint-bilateral weights (spatial_row / expanded_geometric_weights: the same operations in the same
// order), shared by the upsampling kernels. Reads binding 0 `gb` (full-resolution planes: depth.Z 0, N.X/Y/Z 1-3)
// and binding 1 `lowb` (the low-resolution payload, C planes of lw x lh). jb_weights(P) returns the four taps'
// low-resolution offsets and their weights; jb_value(j, c) the payload value of a tap. Includes sampling_grid_glsl()
// (below): a kernel that uses it declares neither.
std::string_view joint_bilateral_glsl();

// GLSL of the frame's sampling grid: the uniforms ivec2 u_full, u_low (full and low resolution); int u_k, u_sx,
// u_sy (the factor and this frame's jitter offset), u_C (payload channels); uint u_n, u_ln (full- and
// low-resolution plane sizes); and gather_low_geometry's validity of low-resolution sample q, `bool low_valid(uint
// q)`: finite geometry at its full-resolution pixel and a payload that is a sample (is_sample: finite and at most
// kMaxSampleMagnitude, as usable_sample in frame.cpp). low_valid reads `gb` and `lowb` (GpuFrame's bindings 0, 1).
std::string_view sampling_grid_glsl();
// Sets those uniforms from the frame.
void set_sampling_grid_uniforms(const gpu::Program& program, const FrameContext& f);

// Sets the uniforms joint_bilateral_glsl() reads from the frame (the constants computed on the host exactly as the
// C++ kernels compute them), set_sampling_grid_uniforms() included.
void set_joint_bilateral_uniforms(const gpu::Program& program, const FrameContext& f);

// Sets `uniform float u_luma[16]`, the luminance weights of the payload channels (FrameContext::luma), 0 past f.C:
// the kernels that take a luminance of the payload (herzog's eq. 8 gradient, taau's locks) declare it so.
void set_luma_uniform(const gpu::Program& program, const FrameContext& f);

// A state file's plane and the GPU buffer that holds it between frames: plane `p` of `buffer` (its width x height)
// into the state as `name` (put_plane; save() cannot report an error: a failed download leaves the plane out, and
// load() names it), and back (get_plane: an Input error names a missing plane).
void save_plane(const gpu::ImageBuffer& buffer, int p, Image& state, const std::string& name);
Status load_plane(const Image& state, const std::string& name, gpu::ImageBuffer& buffer, int p,
                  StateValues values = StateValues::Any);

// A state file's previous depth (and ids, when it has them) into planes 0 and 1 of `prevg` (the C++ states'
// PreviousGeometry, read by get_previous); `has_prev_id` says whether the ids were there.
Status upload_previous_geometry(const Image& state, const Geometry& g, gpu::ImageBuffer& prevg, bool& has_prev_id);
// Its inverse for save(): planes 0 (and 1 when `has_prev_id`) of `prevg` into the state as the C++ states write
// them (put_previous). save() cannot report an error: a failed download leaves the planes out, and load() names them.
void save_previous_geometry(const gpu::ImageBuffer& prevg, bool has_prev_id, const Geometry& g, Image& state);

// One frame's inputs on the GPU: `gb` (binding 0) the full-resolution planes depth.Z, N.X, N.Y, N.Z, motion.X,
// motion.Y, prevDepth.Z, id (planes 0-7; motion, warped depth and id uploaded only when `history_layers` and
// present); `low` (binding 1) the C low-resolution payload planes.
struct GpuFrame {
  gpu::ImageBuffer gb, low;
  Status upload(const std::shared_ptr<gpu::Context>& context, const FrameContext& f, bool history_layers);
  void bind() const {
    gb.bind(0);
    low.bind(1);
  }
};

// What the GPU states with a history (temporal, herzog, taau, drobot) share: the context and the counters their
// kernels count into (binding 15), the frame's inputs, the two output parities of OutputPair (out_[cur_] this
// frame's, the other the previous output) and the previous frame's geometry (prevg_: depth, ids), the result and
// run()'s status (run() itself cannot return an error: the Upsampler asks run_status()), the kernel timing. A state
// implements run_gpu().
class GpuHistoryState : public MethodState, public gpu::TimedKernel {
 public:
  Image& run(const FrameContext& f, bool history, FrameStats& stats) final {
    status_ = run_gpu(f, history, stats);
    return result_;
  }
  Status run_status() const final { return status_; }
  gpu::KernelTiming last_timing() const final { return timing_; }

 protected:
  GpuHistoryState(std::shared_ptr<gpu::Context> context, gpu::ImageBuffer counters, const Geometry& g)
      : ctx_(std::move(context)), counters_(std::move(counters)), g_(g), timer_(ctx_) {}
  virtual Status run_gpu(const FrameContext& f, bool history, FrameStats& stats) = 0;

  // The state file's `history.<c>` planes from / into planes 0..C-1 of out_[cur_] (save() cannot report an error:
  // a failed download leaves the plane out, and load() names it).
  void save_history(Image& state) const;
  Status load_history(const Image& state);
  // Binds the buffers every history kernel reads and writes at the bindings its GLSL declares: the frame (GpuFrame:
  // 0, 1), this frame's output out_[cur_] (2), the previous output (3, the history) and the previous geometry
  // prevg_ (4).
  void bind_history_buffers() const {
    frame_.bind();
    out_[cur_].bind(2);
    out_[1 - cur_].bind(3);
    prevg_.bind(4);
  }
  // PreviousGeometry::store: this frame's depth and ids (GpuFrame planes 0 and 7) become the previous frame's.
  Status store_previous_geometry(const FrameContext& f);
  // The frame's output into result_: planes 0..C-1 of out_[cur_] as the payload channels, then with f.debug planes
  // C.. as `debug_names` (without f.debug those channels are removed from result_).
  Status download_result(const FrameContext& f, std::span<const char* const> debug_names);
  // The end of a frame whose kernels count in counter 0 the pixels that took their history (herzog, taau; temporal's
  // and drobot's kernels count otherwise): the output (download_result), this frame's geometry kept
  // (store_previous_geometry), and the FrameStats: every other pixel a hole, every pixel without `history`.
  Status finish_frame(const FrameContext& f, bool history, std::span<const char* const> debug_names,
                      FrameStats& stats);

  std::shared_ptr<gpu::Context> ctx_;
  gpu::ImageBuffer counters_;
  Geometry g_;
  gpu::Timer timer_;
  GpuFrame frame_;
  gpu::ImageBuffer out_[2], prevg_;
  int cur_ = 0;
  bool has_prev_id_ = false;
  Image result_;
  Status status_;
  gpu::KernelTiming timing_;
};

}  // namespace temporal::upsample
