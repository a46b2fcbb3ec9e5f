// Upsampler: validation of a frame's inputs, the per-frame context, the method's state (created per frame
// geometry, saved and resumed), shader splitting (seed 000 section 4, demodulation) and the antialiasing downsample.
#include "method.h"

#include "temporal/core/jitter.h"
#include "temporal/core/parallel.h"
#include "temporal/gpu/device.h"

#include <algorithm>
#include <atomic>
#include <chrono>
#include <cmath>
#include <optional>

namespace temporal::upsample {
namespace {

std::string dims(int w, int h) { return std::to_string(w) + "x" + std::to_string(h); }

// Albedo below this is not divided by (black or nearly black surfaces, background): the payload passes
// through unchanged there, and the same rule on the way back keeps the round trip exact.
constexpr float kMinAlbedo = 1.0e-3f;

// The albedo channel of a payload channel: "R"/"X.R" -> "albedo.R" (also G, B); "" for other channels.
std::string albedo_channel(const std::string& c) {
  const bool colour = c.size() == 1 || (c.size() > 2 && c[c.size() - 2] == '.');
  const char last = c.empty() ? ' ' : c.back();
  if (!colour || (last != 'R' && last != 'G' && last != 'B')) return {};
  return std::string("albedo.") + last;
}

bool is_colour(const std::string& n) { return n.size() == 1 || (n.size() > 2 && n[n.size() - 2] == '.'); }

// Header keys of a state file (`temporal:<key>`).
constexpr const char* kStateMethod = "upsampleStateOf";
constexpr const char* kStateSize = "upsampleStateSize";  // "W H k"
constexpr const char* kStateChannels = "upsampleStateChannels";
constexpr const char* kStateLayout = "upsampleStateLayout";
constexpr const char* kStateDemodulated = "upsampleStateDemodulated";

std::string size_text(const Geometry& g) {
  return std::to_string(g.W) + " " + std::to_string(g.H) + " " + std::to_string(g.k);
}

}  // namespace

// Options::demodulate: the demodulated low-resolution planes and the remodulated output (the method's own
// result, and so its history, stays demodulated).
struct Demodulation {
  std::vector<std::vector<float>> low;  // per channel, lw x lh
  std::vector<const float*> albedo;     // per channel: the G-buffer albedo plane, nullptr = not a colour channel
  Image out;
};

struct Upsampler::Impl {
  Options options;
  const MethodEntry* entry = nullptr;
  FrameContext f;
  Geometry geometry;
  std::unique_ptr<MethodState> state;
  std::shared_ptr<gpu::Context> gpu;  // --device gpu: the run's context (made with the first state)
  bool have_history = false;
  std::optional<Image> pending;  // a loaded state, applied at the next frame
  std::string pending_source;    // the file it came from (load_state), for the errors found when it is applied
  Demodulation demod;
  Image aa;  // antialiasing variant: downsampled output

  Status validate(const Image& gbuffer, const Image& low, std::span<const std::string> channels,
                  const FrameNames& names, int& sx, int& sy) const;
  void build_context(const Image& gbuffer, const Image& low, std::span<const std::string> channels, int sx, int sy);
  Status prepare_state(std::span<const std::string> channels, const FrameNames& names);
  void demodulate_low();
  Image* remodulate(Image* result, std::span<const std::string> channels);
  Image* downsample(Image* result);
};

Status Upsampler::Impl::validate(const Image& gbuffer, const Image& low, std::span<const std::string> channels,
                                 const FrameNames& names, int& sx, int& sy) const {
  const Options& o = options;
  const std::string& gname = names.gbuffer;
  const std::string& lname = names.input;
  // The runner's checks and messages (temporal/io/runner.h), for callers of the library too.
  std::vector<LayerNeed> needs = entry->layers(o);
  if (o.demodulate) needs.push_back({"albedo", true, "needed by --demodulate"});
  if (Status s = check_gbuffer_layers(gbuffer, needs, gname); !s) return s;
  if (channels.empty()) return Error::input(lname, "no payload channels selected");
  if (channels.size() > 16)
    return Error::usage("at most 16 payload channels per run (" + std::to_string(channels.size()) +
                        " selected): split --layer over several runs");
  for (const auto& c : channels)
    if (!low.plane(c))
      return Error::input(lname, "no float channel '" + c + "' (have: " + join_names(low.channel_names()) + ")");
  const FrameMetadata& lm = low.metadata();
  if (!lm.jitter_factor)
    return Error::input(lname, "no temporal:jitterFactor in the header: upsample-st needs the low-resolution "
                               "shading of render-gbuffer --outputs shade (docs/conventions.md, Jitter)");
  const int k = *lm.jitter_factor;
  if (k < 1 || k > 64) return Error::input(lname, "temporal:jitterFactor " + std::to_string(k) + " is out of range 1..64");
  if (gbuffer.width() != k * low.width() || gbuffer.height() != k * low.height())
    return Error::input(lname, "size mismatch: G-buffer " + dims(gbuffer.width(), gbuffer.height()) + " (" + gname +
                                   ") must be k = " + std::to_string(k) + " times the input " +
                                   dims(low.width(), low.height()) + " per axis (full = k * low)");
  const int m = std::max(1, o.aa_factor);
  if (gbuffer.width() % m || gbuffer.height() % m)
    return Error::input(gname, "the antialiasing factor " + std::to_string(m) + " does not divide the G-buffer size " +
                                   dims(gbuffer.width(), gbuffer.height()));
  if (lm.jitter) {
    const float fx = (lm.jitter->x + 0.5f) * k - 0.5f, fy = (lm.jitter->y + 0.5f) * k - 0.5f;
    sx = int(std::lround(fx));
    sy = int(std::lround(fy));
    if (std::abs(fx - sx) > 1e-3f * k || std::abs(fy - sy) > 1e-3f * k || sx < 0 || sx >= k || sy < 0 || sy >= k)
      return Error::input(lname, "temporal:jitter (" + std::to_string(lm.jitter->x) + ", " +
                                     std::to_string(lm.jitter->y) + ") is not a position of the regular " +
                                     std::to_string(k) + "x" + std::to_string(k) +
                                     " pattern; render with render-gbuffer --jitter regular");
  } else if (lm.jitter_index) {
    const int i = *lm.jitter_index;
    if (i < 0 || i >= k * k)
      return Error::input(lname, "temporal:jitterIndex " + std::to_string(i) + " is out of range 0.." + std::to_string(k * k - 1));
    const glm::ivec2 s = regular_subpixel(k, i);  // the pattern's order (docs/conventions.md, "Jitter")
    sx = s.x;
    sy = s.y;
  } else {
    return Error::input(lname, "no temporal:jitter or temporal:jitterIndex in the header (docs/conventions.md, Jitter)");
  }
  if (o.demodulate) {
    int n = 0;
    for (const auto& c : channels) {
      const std::string a = albedo_channel(c);
      if (a.empty()) continue;
      if (!gbuffer.plane(a))
        return Error::input(gname, "no channel '" + a + "' for --demodulate (have: " +
                                       join_names(gbuffer.channel_names()) +
                                       "); render the G-buffer with render-gbuffer --outputs gbuffer");
      ++n;
    }
    if (n == 0)
      return Error::usage("--demodulate needs colour channels (R, G, B or LAYER.R, .G, .B) in the payload; "
                          "the selected ones are " +
                          join_names(std::vector<std::string>(channels.begin(), channels.end())));
  }
  return Status::ok();
}

void Upsampler::Impl::build_context(const Image& gbuffer, const Image& low, std::span<const std::string> channels,
                                    int sx, int sy) {
  const Options& o = options;
  const int k = *low.metadata().jitter_factor;
  f.options = &options;
  f.debug = o.debug_layers;
  f.W = gbuffer.width();
  f.H = gbuffer.height();
  f.lw = low.width();
  f.lh = low.height();
  f.grid = {k, sx, sy};
  f.C = int(channels.size());
  f.low.clear();
  for (const auto& c : channels) f.low.push_back(low.plane(c));
  f.z = gbuffer.plane("depth.Z");
  f.nx = gbuffer.plane("N.X");
  f.ny = gbuffer.plane("N.Y");
  f.nz = gbuffer.plane("N.Z");
  f.mx = gbuffer.plane("motion.X");
  f.my = gbuffer.plane("motion.Y");
  f.id = gbuffer.uint_plane("id");
  f.prev_z = o.no_depth_velocity ? nullptr : gbuffer.plane("prevDepth.Z");
  // Scalar "norm" of the payload for the temporal gradient (seed 000 3.5.1): luminance of R,G,B triples.
  f.luma.assign(f.C, 0.0f);
  float total = 0;
  for (int c = 0; c < f.C; ++c) {
    const std::string& n = channels[c];
    const char last = n.empty() ? ' ' : n.back();
    f.luma[c] = !is_colour(n) ? 1.0f : last == 'R' ? 0.2126f : last == 'G' ? 0.7152f : last == 'B' ? 0.0722f : 1.0f;
    total += f.luma[c];
  }
  for (auto& w : f.luma) w /= total;
  f.cols.build(f.W, f.lw, k, sx);
  f.rows.build(f.H, f.lh, k, sy);
  if (o.demodulate) {
    demod.albedo.assign(channels.size(), nullptr);
    for (std::size_t c = 0; c < channels.size(); ++c)
      if (const std::string a = albedo_channel(channels[c]); !a.empty()) demod.albedo[c] = gbuffer.plane(a);
  }
}

// sigma_d (seed 000 section 3.1: 3% of far - near) and the depth range of Listing 7.1, from the headers.
static Status depth_scales(const Options& o, const Image& gbuffer, const Image& low, FrameContext& f,
                           const std::string& gname) {
  const FrameMetadata& gm = gbuffer.metadata();
  const FrameMetadata& lm = low.metadata();
  std::optional<float> near_clip = gm.near_clip ? gm.near_clip : lm.near_clip;
  std::optional<float> far_clip = gm.far_clip ? gm.far_clip : lm.far_clip;
  f.depth_range = 1.0f;
  if (near_clip && far_clip && *far_clip > *near_clip) f.depth_range = *far_clip - *near_clip;
  if (o.sigma_depth > 0) {
    f.sigma_d = o.sigma_depth;
    if (!(near_clip && far_clip)) f.depth_range = o.sigma_depth / std::max(1e-6f, o.sigma_depth_fraction);
  } else if (near_clip && far_clip && *far_clip > *near_clip) {
    f.sigma_d = o.sigma_depth_fraction * f.depth_range;
  } else {
    return Error::input(gname, "no clipNear/clipFar in the header to derive sigma_d (3% of far - near); "
                               "pass --sigma-depth in world units");
  }
  return Status::ok();
}

// A new geometry (first frame, size, k or channels changed) discards the history and re-creates the method's
// state; a loaded state (load_state) replaces it when its sizes match.
Status Upsampler::Impl::prepare_state(std::span<const std::string> channels, const FrameNames& names) {
  const Geometry g{f.W, f.H, f.grid.k, f.lw, f.lh, std::vector<std::string>(channels.begin(), channels.end())};
  if (!state || !(g == geometry)) {
    geometry = g;
    // The implementation on --device (check() made sure the method has one there).
    const auto* implementation = find_implementation(*entry, options.device);
    if (!implementation) return check_method_device(*entry, options.device);
    // By the device, not the factory's kind: an adapter with the CPU signature registered for the GPU (one that
    // makes its own context) still runs there, and the headers name the device's context.
    if (options.device == kGpuDevice && !gpu) {
      auto context = gpu::context_for_device(options.device);
      if (!context) return context.error();
      gpu = std::move(*context);
    }
    auto made = implementation->make(gpu, options, geometry);
    if (!made) return made.error();
    state = std::move(*made);
    have_history = false;
  }
  if (!pending) return Status::ok();
  const FrameMetadata& md = pending->metadata();
  const std::string size = md.extra.count(kStateSize) ? md.extra.at(kStateSize) : "";
  const std::string chans = md.extra.count(kStateChannels) ? md.extra.at(kStateChannels) : "";
  if (size != size_text(g) || chans != join_names(g.channels) || pending->width() != g.W || pending->height() != g.H)
    return Error::input(names.input, "the state of --state-in is for frames of " + size + " (width height k) and "
                                     "channels " + chans + ", but this frame is " + size_text(g) + " with channels " +
                                     join_names(g.channels) + ": resume with the sequence and --layer the state was "
                                     "written for");
  if (Status s = state->load(*pending); !s) {
    Error e = s.error();
    if (e.file.empty()) e.file = pending_source;  // the state file's error, not the frame's
    return e;
  }
  pending.reset();
  have_history = true;
  return Status::ok();
}

void Upsampler::Impl::demodulate_low() {
  // Low-resolution sample (x, y) lies on full-resolution pixel (k x + sx, k y + sy) (docs/conventions.md).
  const int k = f.grid.k, sx = f.grid.sx, sy = f.grid.sy;
  demod.low.resize(f.C);
  for (int c = 0; c < f.C; ++c) {
    if (!demod.albedo[c]) continue;
    auto& dst = demod.low[c];
    dst.resize(std::size_t(f.lw) * f.lh);
    const float* src = f.low[c];
    const float* alb = demod.albedo[c];
    parallel_rows(f.lh, [&](int y0, int y1) {
      for (int y = y0; y < y1; ++y) {
        const float* ar = alb + std::size_t(k * y + sy) * f.W + sx;
        const float* sr = src + std::size_t(y) * f.lw;
        float* dr = dst.data() + std::size_t(y) * f.lw;
        for (int x = 0; x < f.lw; ++x) {
          const float a = ar[std::size_t(k) * x];
          dr[x] = a >= kMinAlbedo ? sr[x] / a : sr[x];
        }
      }
    });
    f.low[c] = dst.data();
  }
}

// Multiplies by the full-resolution albedo into a separate image: the method's result stays the (demodulated)
// history.
Image* Upsampler::Impl::remodulate(Image* result, std::span<const std::string> channels) {
  Image& out = demod.out;
  if (out.width() != f.W || out.height() != f.H) out = Image(f.W, f.H);
  for (const auto& name : result->channel_names()) {
    const float* src = result->plane(name);
    float* dst = out.add_channel(name);
    const float* alb = nullptr;
    for (int c = 0; c < f.C; ++c)
      if (channels[c] == name) alb = demod.albedo[c];
    parallel_rows(f.H, [&](int y0, int y1) {
      const std::size_t b = std::size_t(y0) * f.W, e = std::size_t(y1) * f.W;
      if (!alb) {
        std::copy(src + b, src + e, dst + b);
        return;
      }
      for (std::size_t i = b; i < e; ++i) dst[i] = alb[i] >= kMinAlbedo ? src[i] * alb[i] : src[i];
    });
  }
  return &out;
}

// Seed 000 section 4: the upsampled result at m x m the display resolution, box-downsampled.
Image* Upsampler::Impl::downsample(Image* result) {
  const int m = options.aa_factor;
  const int ow = f.W / m, oh = f.H / m;
  if (aa.width() != ow || aa.height() != oh) aa = Image(ow, oh);
  for (const auto& name : result->channel_names()) {
    const float* src = result->plane(name);
    float* dst = aa.add_channel(name);
    const float inv = 1.0f / float(m * m);
    parallel_rows(oh, [&](int y0, int y1) {
      for (int y = y0; y < y1; ++y) {
        float* d = dst + std::size_t(y) * ow;
        std::fill(d, d + ow, 0.0f);
        for (int j = 0; j < m; ++j) {
          const float* r = src + std::size_t(y * m + j) * f.W;
          for (int x = 0; x < ow; ++x)
            for (int i = 0; i < m; ++i) d[x] += r[x * m + i];
        }
        for (int x = 0; x < ow; ++x) d[x] *= inv;
      }
    });
  }
  return &aa;
}

Upsampler::Upsampler(Options options) : impl_(std::make_unique<Impl>()) {
  impl_->options = std::move(options);
  impl_->entry = find_entry(impl_->options.method);
}
Upsampler::~Upsampler() = default;

const Options& Upsampler::options() const { return impl_->options; }

const gpu::Context* Upsampler::gpu_context() const { return impl_->gpu.get(); }

void Upsampler::reset() { impl_->have_history = false; }

bool Upsampler::has_state() const { return impl_->entry && impl_->entry->info.has_state; }

Expected<Image*> Upsampler::process(const Image& gbuffer, const Image& low, std::span<const std::string> channels,
                                    bool cut, FrameStats* stats_out, const FrameNames& names) {
  const auto t0 = std::chrono::steady_clock::now();
  Impl& u = *impl_;
  if (!u.entry) return check(u.options).error();
  int sx = 0, sy = 0;
  if (Status s = u.validate(gbuffer, low, channels, names, sx, sy); !s) return s.error();
  u.build_context(gbuffer, low, channels, sx, sy);
  if (Status s = depth_scales(u.options, gbuffer, low, u.f, names.gbuffer); !s) return s.error();
  if (Status s = u.prepare_state(channels, names); !s) return s.error();
  FrameStats stats;
  const FrameMetadata &gm = gbuffer.metadata(), &lm = low.metadata();
  if (cut || gm.camera_cut.value_or(false) || lm.camera_cut.value_or(false)) u.have_history = false;
  stats.history_reset = !u.have_history;
  {
    // In parallel chunks: the first read of this frame's payload (from memory), serial before (~1 % of drobot's
    // samples at 1280x1024, with the other core idle).
    const std::size_t n = std::size_t(u.f.lw) * u.f.lh;
    std::atomic<std::size_t> non_finite{0};
    parallel_chunks(n, [&](std::size_t b, std::size_t e) {
      std::size_t m = 0;
      for (int c = 0; c < u.f.C; ++c) m += count_non_finite({u.f.low[c] + b, e - b});
      non_finite.fetch_add(m, std::memory_order_relaxed);
    }, std::size_t(1) << 14);
    stats.non_finite_input += non_finite.load();
  }
  if (u.options.demodulate) u.demodulate_low();
  if (u.state->gathers_low_geometry())
    clear_low_geometry(u.f);
  else
    gather_low_geometry(u.f);
  Image* result = &u.state->run(u.f, u.have_history, stats);
  if (Status s = u.state->run_status(); !s) return s.error();
  u.have_history = true;
  if (u.options.demodulate) result = u.remodulate(result, channels);
  if (u.options.aa_factor > 1) result = u.downsample(result);
  result->metadata() = FrameMetadata{};
  stats.wall_ms = std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count();
  // On the GPU: the kernels' time (gpu/device.h); the frame's checks, uploads and downloads are in wall_ms.
  const gpu::ComputeTime time =
      gpu::compute_time(u.gpu ? dynamic_cast<const gpu::TimedKernel*>(u.state.get()) : nullptr, stats.wall_ms);
  stats.compute_ms = time.ms;
  stats.compute_clock = time.clock;
  if (stats_out) *stats_out = stats;
  return result;
}

Expected<Image> Upsampler::save_state() const {
  const Impl& u = *impl_;
  if (!has_state()) return Error::usage("--method " + u.options.method + " keeps no state: drop --state-in / --state-out");
  if (!u.state || !u.have_history) return Error::usage("no state to save: no frame has been upsampled since the last reset");
  Image state(u.geometry.W, u.geometry.H);
  FrameMetadata& md = state.metadata();
  md.extra[kStateMethod] = u.options.method;
  md.extra[kStateSize] = size_text(u.geometry);
  md.extra[kStateChannels] = join_names(u.geometry.channels);
  md.extra[kStateDemodulated] = u.options.demodulate ? "1" : "0";
  if (u.entry->state_layout) md.extra[kStateLayout] = u.entry->state_layout(u.options);
  u.state->save(state);
  return state;
}

Status Upsampler::load_state(const Image& state, std::string source) {
  Impl& u = *impl_;
  if (!has_state()) return Error::usage("--method " + u.options.method + " keeps no state: drop --state-in / --state-out");
  const auto& extra = state.metadata().extra;
  auto attr = [&](const char* key) { return extra.count(key) ? extra.at(key) : std::string(); };
  const std::string method = attr(kStateMethod);
  if (method.empty())
    return Error::input({}, "not an upsample-st state (no temporal:upsampleStateOf in its header): pass a file "
                            "written by upsample-st --state-out");
  if (method != u.options.method)
    return Error::usage("the state was written by --method " + method + ", this run uses --method " +
                        u.options.method + ": resume with the method that wrote it");
  const std::string layout = u.entry->state_layout ? u.entry->state_layout(u.options) : "";
  if (attr(kStateLayout) != layout)
    return Error::usage("the state was written with " + attr(kStateLayout) + ", this run has " + layout +
                        ": resume with the options that wrote it");
  if (attr(kStateDemodulated) != (u.options.demodulate ? "1" : "0"))
    return Error::usage(std::string("the state was written ") + (u.options.demodulate ? "without" : "with") +
                        " --demodulate: resume with the same --demodulate setting");
  u.pending = state;
  u.pending_source = std::move(source);
  return Status::ok();
}

}  // namespace temporal::upsample
