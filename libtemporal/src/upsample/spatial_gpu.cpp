// `spatial` (spatial.cpp) as one GLSL compute kernel, and the joint-bilateral GLSL shared with temporal_gpu.cpp.
// The low-resolution samples' geometry (gather_low_geometry) is read in the kernel from the full-resolution
// G-buffer at the sample's pixel (k x + sx, k y + sy), the same values; the tap tables (TapTable) are the same
// integer formulas; 1 / k and d / k are computed on the host as the C++ kernels compute them.
#include "gpu_methods.h"
#include "temporal/gpu/glsl.h"
#include "temporal/gpu/timer.h"

#include <algorithm>
#include <mutex>

namespace temporal::upsample {

std::string_view joint_bilateral_glsl() {
  static const std::string text = gpu::glsl::float_constant("kKernelEpsilon", kKernelEpsilon) +
                                  std::string(sampling_grid_glsl()) + R"(
uniform float u_inv_k, u_inv_sn2, u_inv_sd2;
uniform float u_frac[64];  // float(d) / float(k), d = 0..k-1

// std::max / std::min: (a < b) ? b : a, which returns `a` when b is NaN (the C++ kernels' NaN behaviour).
float std_max(float a, float b) { return (a < b) ? b : a; }
int floor_div(int a, int b) { return (a >= 0) ? a / b : -((-a + b - 1) / b); }

// geometric_weight (joint_bilateral.h) and sample_weight (upsample_internal.h).
float geometric_weight(float dot_, float dz) {
  const float xn = std_max(0.0, 1.0 - dot_);
  const float tn = std_max(kKernelEpsilon, 1.0 - xn * xn * u_inv_sn2);
  const float td = std_max(kKernelEpsilon, 1.0 - dz * dz * u_inv_sd2);
  return tn * tn * tn * td * td * td;
}

// A low-resolution sample: its full-resolution pixel's geometry, valid when that geometry and every payload
// channel are finite (gather_low_geometry).
float sample_weight_at(uint q, float zi, float ax, float ay, float az) {
  const uint lx = q % uint(u_low.x), ly = q / uint(u_low.x);
  const uint g = (uint(u_k) * ly + uint(u_sy)) * uint(u_full.x) + uint(u_sx) + uint(u_k) * lx;
  const float lz = gb[g], nx = gb[u_n + g], ny = gb[2u * u_n + g], nz = gb[3u * u_n + g];
  const float lv = low_valid(q) ? 1.0 : 0.0;
  const float dot_ = ax * nx + ay * ny + az * nz;
  const float w = geometric_weight(dot_, zi - lz) * lv;
  return w >= 0.0 ? w : 0.0;
}

struct JB {
  uint q[4];    // low-resolution offsets of taps 00, 01, 10, 11
  float w[4];   // their weights (geometric x existence x hat)
  bool computed;  // the pixel was shaded this frame (offset 0 in both axes)
  bool valid0;    // tap 00's sample is valid (lvalid)
};

// spatial_row's weights for pixel P (TapTable: taps x0 = floor((X - sx) / k), x0 + 1, clamped; existence 0/1).
JB jb_weights(ivec2 P) {
  const int k = u_k, lw = u_low.x, lh = u_low.y;
  const int x0 = floor_div(P.x - u_sx, k), y0 = floor_div(P.y - u_sy, k);
  const int dx = P.x - u_sx - k * x0, dy = P.y - u_sy - k * y0;
  const float cv0 = (x0 >= 0 && x0 < lw) ? 1.0 : 0.0, cv1 = (x0 + 1 >= 0 && x0 + 1 < lw) ? 1.0 : 0.0;
  const float vy0 = (y0 >= 0 && y0 < lh) ? 1.0 : 0.0, vy1 = (y0 + 1 >= 0 && y0 + 1 < lh) ? 1.0 : 0.0;
  const uint ci0 = uint(clamp(x0, 0, lw - 1)), ci1 = uint(clamp(x0 + 1, 0, lw - 1));
  const uint r0 = uint(clamp(y0, 0, lh - 1)) * uint(lw), r1 = uint(clamp(y0 + 1, 0, lh - 1)) * uint(lw);
  const float fx = float(dx) * u_inv_k, fy = u_frac[dy];
  const uint i = uint(P.y) * uint(u_size.x) + uint(P.x);
  const float zi = gb[i], ax = gb[u_n + i], ay = gb[2u * u_n + i], az = gb[3u * u_n + i];
  JB j;
  j.q[0] = r0 + ci0;
  j.q[1] = r0 + ci1;
  j.q[2] = r1 + ci0;
  j.q[3] = r1 + ci1;
  j.w[0] = sample_weight_at(j.q[0], zi, ax, ay, az) * cv0 * vy0 * (1.0 - fx) * (1.0 - fy);
  j.w[1] = sample_weight_at(j.q[1], zi, ax, ay, az) * cv1 * vy0 * fx * (1.0 - fy);
  j.w[2] = sample_weight_at(j.q[2], zi, ax, ay, az) * cv0 * vy1 * (1.0 - fx) * fy;
  j.w[3] = sample_weight_at(j.q[3], zi, ax, ay, az) * cv1 * vy1 * fx * fy;
  j.computed = dx == 0 && dy == 0;
  j.valid0 = low_valid(j.q[0]);
  return j;
}

float jb_sum(JB j) { return j.w[0] + j.w[1] + j.w[2] + j.w[3]; }

// Eq. 1 for channel c: invalid samples carry weight 0 and their value (possibly NaN) is replaced by 0.
float jb_value(JB j, int c) {
  const uint b = uint(c) * u_ln;
  const float ws = jb_sum(j);
  const float a = j.w[0] > 0.0 ? lowb[b + j.q[0]] : 0.0, bb = j.w[1] > 0.0 ? lowb[b + j.q[1]] : 0.0;
  const float cc = j.w[2] > 0.0 ? lowb[b + j.q[2]] : 0.0, d = j.w[3] > 0.0 ? lowb[b + j.q[3]] : 0.0;
  const float v = j.w[0] * a + j.w[1] * bb + j.w[2] * cc + j.w[3] * d;
  return ws > 0.0 ? v / ws : 0.0;
}

)";
  return text;
}

void set_joint_bilateral_uniforms(const gpu::Program& program, const FrameContext& f) {
  const Options& o = *f.options;
  const int k = f.grid.k;
  set_sampling_grid_uniforms(program, f);
  program.set("u_inv_k", 1.0f / float(k));
  float frac[64] = {};
  for (int d = 0; d < k && d < 64; ++d) frac[d] = float(d) / float(k);
  program.set("u_frac", frac, 64);
  program.set("u_inv_sn2", 1.0f / (o.sigma_normal * o.sigma_normal));
  program.set("u_inv_sd2", 1.0f / (f.sigma_d * f.sigma_d));
}

Status upload_previous_geometry(const Image& state, const Geometry& g, gpu::ImageBuffer& prevg, bool& has_prev_id) {
  PreviousGeometry prev;
  if (Status s = get_previous(state, prev, g.W, g.H); !s) return s;
  if (Status s = prevg.upload(0, prev.z.data()); !s) return s;
  has_prev_id = !prev.id.empty();
  if (has_prev_id)
    if (Status s = prevg.upload(1, prev.id.data()); !s) return s;
  return Status::ok();
}

void save_previous_geometry(const gpu::ImageBuffer& prevg, bool has_prev_id, const Geometry& g, Image& state) {
  PreviousGeometry prev;
  prev.z.resize(std::size_t(g.W) * g.H);
  if (!prevg.download(0, prev.z.data())) return;  // left out: load() names the missing plane
  if (has_prev_id) {
    prev.id.resize(prev.z.size());
    if (!prevg.download(1, prev.id.data())) prev.id.clear();
  }
  put_previous(state, prev, g.W, g.H);
}

Status GpuFrame::upload(const std::shared_ptr<gpu::Context>& context, const FrameContext& f, bool history_layers) {
  if (gb.width() != f.W || gb.height() != f.H) {
    auto b = gpu::ImageBuffer::create(context, f.W, f.H, 8);
    if (!b) return b.error();
    gb = std::move(*b);
  }
  if (low.width() != f.lw || low.height() != f.lh || low.planes() != f.C) {
    auto b = gpu::ImageBuffer::create(context, f.lw, f.lh, f.C);
    if (!b) return b.error();
    low = std::move(*b);
  }
  const float* planes[4] = {f.z, f.nx, f.ny, f.nz};
  for (int p = 0; p < 4; ++p)
    if (Status s = gb.upload(p, planes[p]); !s) return s;
  if (history_layers) {
    if (f.mx)
      if (Status s = gb.upload(4, f.mx); !s) return s;
    if (f.my)
      if (Status s = gb.upload(5, f.my); !s) return s;
    if (f.prev_z)
      if (Status s = gb.upload(6, f.prev_z); !s) return s;
    if (f.id)
      if (Status s = gb.upload(7, f.id); !s) return s;
  }
  for (int c = 0; c < f.C; ++c)
    if (Status s = low.upload(c, f.low[std::size_t(c)]); !s) return s;
  return Status::ok();
}

void save_plane(const gpu::ImageBuffer& buffer, int p, Image& state, const std::string& name) {
  std::vector<float> plane(buffer.pixel_count());
  if (buffer.download(p, plane.data())) put_plane(state, name, plane.data(), buffer.width(), buffer.height());
}

Status load_plane(const Image& state, const std::string& name, gpu::ImageBuffer& buffer, int p, StateValues values) {
  std::vector<float> plane(buffer.pixel_count());
  if (Status s = get_plane(state, name, plane.data(), buffer.width(), buffer.height(), values); !s) return s;
  return buffer.upload(p, plane.data());
}

void GpuHistoryState::save_history(Image& state) const {
  for (int c = 0; c < int(g_.channels.size()); ++c)
    save_plane(out_[cur_], c, state, "history." + g_.channels[std::size_t(c)]);
}

Status GpuHistoryState::load_history(const Image& state) {
  for (int c = 0; c < int(g_.channels.size()); ++c)
    if (Status s = load_plane(state, "history." + g_.channels[std::size_t(c)], out_[cur_], c, StateValues::Finite); !s)
      return s;
  return Status::ok();
}

Status GpuHistoryState::store_previous_geometry(const FrameContext& f) {
  if (Status s = prevg_.copy_plane(frame_.gb, 0, 0); !s) return s;
  has_prev_id_ = f.id != nullptr;
  if (has_prev_id_)
    if (Status s = prevg_.copy_plane(frame_.gb, 7, 1); !s) return s;
  return Status::ok();
}

Status GpuHistoryState::download_result(const FrameContext& f, std::span<const char* const> debug_names) {
  if (result_.width() != f.W || result_.height() != f.H) result_ = Image(f.W, f.H);
  for (int c = 0; c < f.C; ++c)
    if (Status s = out_[cur_].download(c, result_, g_.channels[std::size_t(c)]); !s) return s;
  for (std::size_t d = 0; d < debug_names.size(); ++d) {
    if (f.debug) {
      if (Status s = out_[cur_].download(f.C + int(d), result_, debug_names[d]); !s) return s;
    } else {
      result_.remove_channel(debug_names[d]);
    }
  }
  return Status::ok();
}

Status GpuHistoryState::finish_frame(const FrameContext& f, bool history, std::span<const char* const> debug_names,
                                     FrameStats& stats) {
  if (Status s = download_result(f, debug_names); !s) return s;
  if (Status s = store_previous_geometry(f); !s) return s;
  std::uint32_t counts[4] = {};
  if (Status s = counters_.download(0, counts); !s) return s;
  stats.history_pixels = history ? counts[0] : 0;
  stats.hole_pixels = std::size_t(f.W) * f.H - stats.history_pixels;
  return Status::ok();
}

std::string_view sampling_grid_glsl() {
  return R"(
uniform ivec2 u_full, u_low;
uniform int u_k, u_sx, u_sy, u_C;
uniform uint u_n, u_ln;

bool low_valid(uint q) {
  const uint lx = q % uint(u_low.x), ly = q / uint(u_low.x);
  const uint g = (uint(u_k) * ly + uint(u_sy)) * uint(u_full.x) + uint(u_sx) + uint(u_k) * lx;
  bool ok = is_finite_bits(gb[g]) && is_finite_bits(gb[u_n + g]) && is_finite_bits(gb[2u * u_n + g]) &&
            is_finite_bits(gb[3u * u_n + g]);
  for (int c = 0; c < u_C; ++c) ok = ok && is_sample(lowb[uint(c) * u_ln + q]);
  return ok;
}
)";
}

void set_sampling_grid_uniforms(const gpu::Program& program, const FrameContext& f) {
  program.set_int2("u_full", f.W, f.H);
  program.set_int2("u_low", f.lw, f.lh);
  program.set("u_k", f.grid.k);
  program.set("u_sx", f.grid.sx);
  program.set("u_sy", f.grid.sy);
  program.set("u_C", f.C);
  program.set("u_n", std::uint32_t(std::size_t(f.W) * f.H));
  program.set("u_ln", std::uint32_t(std::size_t(f.lw) * f.lh));
}

void set_luma_uniform(const gpu::Program& program, const FrameContext& f) {
  float luma[16] = {};
  for (int c = 0; c < f.C && c < 16; ++c) luma[c] = f.luma[std::size_t(c)];
  program.set("u_luma", luma, 16);
}

Expected<std::shared_ptr<gpu::Context>> shared_gpu_context() {
  static std::mutex mutex;
  static std::weak_ptr<gpu::Context> shared;
  const std::lock_guard<std::mutex> lock(mutex);
  if (auto live = shared.lock()) return live;
  auto created = gpu::Context::create();
  if (!created) return created.error();
  shared = *created;
  return *created;
}

namespace {

// What a GPU factory that failed leaves in the Upsampler: every call returns the factory's error.
class FailedState final : public MethodState {
 public:
  explicit FailedState(Error e) : status_(std::move(e)) {}
  Image& run(const FrameContext&, bool, FrameStats&) override { return empty_; }
  Status run_status() const override { return status_; }
  void save(Image&) const override {}
  Status load(const Image&) override { return status_; }

 private:
  Status status_;
  Image empty_;
};

}  // namespace

std::unique_ptr<MethodState> state_or_failure(Expected<std::unique_ptr<MethodState>> made) {
  if (!made) return std::make_unique<FailedState>(made.error());
  return std::move(*made);
}

namespace {

constexpr const char* kSpatialMain = R"(
uniform bool u_debug;
void main() {
  ivec2 p;
  uint i;
  if (!pixel_index(p, i)) return;
  const JB j = jb_weights(p);
  for (int c = 0; c < u_C; ++c) outb[uint(c) * u_n + i] = jb_value(j, c);
  if (u_debug) outb[uint(u_C) * u_n + i] = jb_sum(j);  // debug.confidence
}
)";

// Spatial upsampling keeps nothing between frames: its state is its output image.
class SpatialStateGpu final : public MethodState, public gpu::TimedKernel {
 public:
  SpatialStateGpu(std::shared_ptr<gpu::Context> ctx, gpu::Program program, const Geometry& g)
      : ctx_(std::move(ctx)), program_(std::move(program)), g_(g), timer_(ctx_) {}

  Image& run(const FrameContext& f, bool, FrameStats& stats) override {
    status_ = run_gpu(f);
    stats.hole_pixels = 0;
    stats.history_pixels = 0;
    return result_;
  }
  Status run_status() const override { return status_; }
  void save(Image&) const override {}
  Status load(const Image&) override { return Status::ok(); }
  gpu::KernelTiming last_timing() const override { return timing_; }

 private:
  Status run_gpu(const FrameContext& f) {
    if (Status s = frame_.upload(ctx_, f, false); !s) return s;
    if (out_.width() != f.W || out_.height() != f.H || out_.planes() != f.C + 1) {
      auto b = gpu::ImageBuffer::create(ctx_, f.W, f.H, f.C + 1);
      if (!b) return b.error();
      out_ = std::move(*b);
    }
    if (Status s = program_.use(); !s) return s;
    set_joint_bilateral_uniforms(program_, f);
    program_.set("u_debug", int(f.debug));
    frame_.bind();
    out_.bind(2);
    timer_.start();
    if (Status s = program_.dispatch(f.W, f.H); !s) return s;
    timing_.kernel_ms = timer_.stop_ms();
    timing_.clock = timer_.clock();
    // spatial.cpp's streamed_bytes: depth + N, the payload in and out (+ the debug plane).
    const double full = double(f.W) * f.H * 4.0, low = double(f.lw) * f.lh * 4.0;
    timing_.bytes_moved = 4.0 * full + f.C * low + f.C * full + (f.debug ? full : 0.0);
    if (result_.width() != f.W || result_.height() != f.H) result_ = Image(f.W, f.H);
    for (int c = 0; c < f.C; ++c)
      if (Status s = out_.download(c, result_, g_.channels[std::size_t(c)]); !s) return s;
    if (f.debug) {
      if (Status s = out_.download(f.C, result_, "debug.confidence"); !s) return s;
    } else {
      result_.remove_channel("debug.confidence");
    }
    return Status::ok();
  }

  std::shared_ptr<gpu::Context> ctx_;
  gpu::Program program_;
  Geometry g_;
  gpu::Timer timer_;
  GpuFrame frame_;
  gpu::ImageBuffer out_;
  Image result_;
  Status status_;
  gpu::KernelTiming timing_;
};

}  // namespace

Expected<std::unique_ptr<MethodState>> make_spatial_state_gpu(std::shared_ptr<gpu::Context> context,
                                                              const Options&, const Geometry& geometry) {
  if (Status s = gpu::Context::ensure(context); !s) return s.error();
  auto program = gpu::Program::compile(
      context, "spatial",
      {gpu::glsl::prelude(), gpu::glsl::storage(0, "gb"), gpu::glsl::storage(1, "lowb"),
       gpu::glsl::storage(2, "outb"), joint_bilateral_glsl(), kSpatialMain});
  if (!program) return program.error();
  return std::unique_ptr<MethodState>(new SpatialStateGpu(std::move(context), std::move(*program), geometry));
}

}  // namespace temporal::upsample
