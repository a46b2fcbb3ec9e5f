// Upsampler: validation of a frame's inputs, state management, dispatch to the methods, the
// antialiasing downsample (seed 000 section 4) and the shared joint-bilateral row kernel.
#include "upsample_internal.h"

#include "temporal/core/parallel.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstring>
#include <sstream>

namespace temporal::upsample {

Expected<Method> parse_method(const std::string& name) {
  if (name == "spatial") return Method::Spatial;
  if (name == "temporal") return Method::Temporal;
  if (name == "herzog") return Method::Herzog;
  if (name == "drobot") return Method::Drobot;
  return Error::usage("unknown method '" + name + "': use spatial, temporal, herzog or drobot");
}

Expected<DrobotMode> parse_drobot_mode(const std::string& name) {
  if (name == "cache") return DrobotMode::Cache;
  if (name == "refresh") return DrobotMode::Refresh;
  return Error::usage("unknown drobot mode '" + name + "': use cache or refresh");
}

const char* method_name(Method m) {
  switch (m) {
    case Method::Spatial: return "spatial";
    case Method::Temporal: return "temporal";
    case Method::Herzog: return "herzog";
    case Method::Drobot: return "drobot";
  }
  return "?";
}

std::vector<std::string> gbuffer_layers(const Options& o) {
  std::vector<std::string> layers = {"depth", "N"};
  if (o.method != Method::Spatial) layers.push_back("motion");
  if ((o.method == Method::Temporal || o.method == Method::Herzog) && o.use_ids) layers.push_back("id");
  if (o.demodulate) layers.push_back("albedo");
  return layers;
}

std::size_t count_non_finite_gbuffer(const Image& g) {
  std::size_t n = 0;
  for (const char* c : {"depth.Z", "N.X", "N.Y", "N.Z", "motion.X", "motion.Y"})
    if (const float* p = g.plane(c)) n += count_non_finite({p, g.pixel_count()});
  return n;
}

namespace {

std::string join(const std::vector<std::string>& v) {
  std::string s;
  for (const auto& x : v) s += (s.empty() ? "" : ", ") + x;
  return s.empty() ? "(none)" : s;
}

std::vector<std::string> split(const std::string& text) {
  std::vector<std::string> out;
  std::stringstream ss(text);
  std::string item;
  while (std::getline(ss, item, ','))
    if (!item.empty()) out.push_back(item);
  return out;
}

std::string dims(int w, int h) { return std::to_string(w) + "x" + std::to_string(h); }

}  // namespace

Expected<std::vector<std::string>> select_channels(const Image& low, const std::string& layers, const std::string& file) {
  std::vector<std::string> out;
  for (const auto& layer : split(layers.empty() ? std::string("rgb") : layers)) {
    std::vector<std::string> names;
    if (layer == "rgb") {
      for (const char* c : {"R", "G", "B"})
        if (low.has_channel(c)) names.push_back(c);
      if (names.size() != 3)
        return Error::input(file, "no R,G,B payload (have: " + join(low.channel_names()) +
                                      "); render it with render-gbuffer --outputs shade, or pick one with --layer");
    } else if (low.has_channel(layer)) {
      names.push_back(layer);
    } else {
      names = low.layer_channels(layer);
      if (names.empty())
        return Error::input(file, "no layer '" + layer + "' (have: " + join(low.channel_names()) + ")");
    }
    for (auto& n : names)
      if (low.channel_type(n) != ChannelType::Float)
        return Error::input(file, "channel '" + n + "' is not float; only float payloads can be upsampled");
    out.insert(out.end(), names.begin(), names.end());
  }
  return out;
}

void TapTable::build(int full, int low, int k, int s) {
  i0.resize(full);
  i1.resize(full);
  d.resize(full);
  v0.resize(full);
  v1.resize(full);
  for (int X = 0; X < full; ++X) {
    const int x0 = JitterGrid::floor_div(X - s, k);
    d[X] = X - s - k * x0;
    v0[X] = (x0 >= 0 && x0 < low) ? 1.0f : 0.0f;
    v1[X] = (x0 + 1 >= 0 && x0 + 1 < low) ? 1.0f : 0.0f;
    i0[X] = std::clamp(x0, 0, low - 1);
    i1[X] = std::clamp(x0 + 1, 0, low - 1);
  }
}

void gather_low_geometry(Upsampler::State& s, const FrameContext& f) {
  const std::size_t n = std::size_t(f.lw) * f.lh;
  s.lz.resize(n);
  s.lnx.resize(n);
  s.lny.resize(n);
  s.lnz.resize(n);
  s.lvalid.resize(n);
  const int k = f.grid.k;
  parallel_rows(f.lh, [&](int y0, int y1) {
    for (int y = y0; y < y1; ++y) {
      const std::size_t src_row = std::size_t(k * y + f.grid.sy) * f.W + f.grid.sx;
      for (int x = 0; x < f.lw; ++x) {
        const std::size_t i = std::size_t(y) * f.lw + x, g = src_row + std::size_t(k) * x;
        s.lz[i] = f.z[g];
        s.lnx[i] = f.nx[g];
        s.lny[i] = f.ny[g];
        s.lnz[i] = f.nz[g];
        // A sample with a non-finite payload or geometry is no sample (its weight becomes 0).
        bool ok = std::isfinite(f.z[g]) && std::isfinite(f.nx[g]) && std::isfinite(f.ny[g]) && std::isfinite(f.nz[g]);
        for (int c = 0; c < f.C; ++c) ok = ok && std::isfinite(f.low[c][i]);
        s.lvalid[i] = ok ? 1.0f : 0.0f;
      }
    }
  });
}

void spatial_row(const Upsampler::State& s, const FrameContext& f, const Options& o, int Y, float* const* out,
                 float* wsum, int X0, int X1) {
  // Four weights per pixel are computed into thread-local rows first (a loop that vectorises, with gathers),
  // then each channel is accumulated in its own unit-stride loop. Restrict-qualified locals let the
  // compiler vectorise without alias checks.
  thread_local std::vector<float> w4;
  w4.resize(std::size_t(f.W) * 4);
  float* __restrict w00 = w4.data();
  float* __restrict w01 = w00 + f.W;
  float* __restrict w10 = w01 + f.W;
  float* __restrict w11 = w10 + f.W;
  const int W = f.W, k = f.grid.k;
  if (X1 < 0) X1 = W;
  const int r0 = s.rows.i0[Y] * f.lw, r1 = s.rows.i1[Y] * f.lw;
  const float vy0 = s.rows.v0[Y], vy1 = s.rows.v1[Y];
  const float fy = float(s.rows.d[Y]) / float(k), inv_k = 1.0f / float(k);
  const float inv_sn2 = 1.0f / (o.sigma_normal * o.sigma_normal), inv_sd2 = 1.0f / (f.sigma_d * f.sigma_d);
  const std::size_t row = std::size_t(Y) * W;
  const float* __restrict z = f.z + row;
  const float* __restrict nx = f.nx + row;
  const float* __restrict ny = f.ny + row;
  const float* __restrict nz = f.nz + row;
  const int* __restrict ci0 = s.cols.i0.data();
  const int* __restrict ci1 = s.cols.i1.data();
  const int* __restrict cd = s.cols.d.data();
  const float* __restrict cv0 = s.cols.v0.data();
  const float* __restrict cv1 = s.cols.v1.data();
  const float* __restrict lz = s.lz.data();
  const float* __restrict lnx = s.lnx.data();
  const float* __restrict lny = s.lny.data();
  const float* __restrict lnz = s.lnz.data();
  const float* __restrict lvalid = s.lvalid.data();
  // Geometric weights (eq. 2-3, shared with the expanded-row kernels: same operations in the same order, so
  // the same bits) times tap existence, then the hat image kernel.
  auto geo = [=](int j, float zi, float ax, float ay, float az) {
    return geometric_weight(zi, ax, ay, az, lnx[j], lny[j], lnz[j], lz[j], lvalid[j], inv_sn2, inv_sd2);
  };
#pragma GCC ivdep
  for (int X = X0; X < X1; ++X) {
    const float fx = float(cd[X]) * inv_k;
    const float zi = z[X], ax = nx[X], ay = ny[X], az = nz[X];
    w00[X] = geo(r0 + ci0[X], zi, ax, ay, az) * cv0[X] * vy0 * (1 - fx) * (1 - fy);
    w01[X] = geo(r0 + ci1[X], zi, ax, ay, az) * cv1[X] * vy0 * fx * (1 - fy);
    w10[X] = geo(r1 + ci0[X], zi, ax, ay, az) * cv0[X] * vy1 * (1 - fx) * fy;
    w11[X] = geo(r1 + ci1[X], zi, ax, ay, az) * cv1[X] * vy1 * fx * fy;
  }
  for (int c = 0; c < f.C; ++c) {
    const float* __restrict l0 = f.low[c] + r0;
    const float* __restrict l1 = f.low[c] + r1;
    float* __restrict o_ = out[c];
#pragma GCC ivdep
    for (int X = X0; X < X1; ++X) {
      const float ws = w00[X] + w01[X] + w10[X] + w11[X];
      // Invalid samples carry weight 0, and their value is replaced by 0 so that a NaN never propagates.
      // Unconditional loads (clamped indices, always valid) and a select: conditional loads would need
      // masked gathers, which keep the loop scalar.
      const float la = l0[ci0[X]], lb = l0[ci1[X]], lc = l1[ci0[X]], ld = l1[ci1[X]];
      const float a = w00[X] > 0 ? la : 0.0f, b = w01[X] > 0 ? lb : 0.0f;
      const float cc = w10[X] > 0 ? lc : 0.0f, d = w11[X] > 0 ? ld : 0.0f;
      const float v = w00[X] * a + w01[X] * b + w10[X] * cc + w11[X] * d;
      o_[X] = ws > 0 ? v / ws : 0.0f;
    }
  }
  if (wsum)
    for (int X = X0; X < X1; ++X) wsum[X] = w00[X] + w01[X] + w10[X] + w11[X];
}

// Options::demodulate: the demodulated low-resolution planes and the remodulated output (the method's own
// result, and so its history, stays demodulated).
struct Upsampler::Demodulation {
  std::vector<std::vector<float>> low;  // per channel, lw x lh
  std::vector<const float*> albedo;     // per channel: the G-buffer albedo plane, nullptr = not a colour channel
  Image out;
};

namespace {
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
}  // namespace

Upsampler::Upsampler(Options options)
    : options_(std::move(options)), state_(std::make_unique<State>()), demod_(std::make_unique<Demodulation>()) {}
Upsampler::~Upsampler() = default;

void Upsampler::reset() { state_->have_history = false; }

std::size_t Upsampler::streamed_bytes(const Options& o, int W, int H, int k, int C) {
  // What a method must at least read and write once per frame: G-buffer planes it reads, the
  // low-resolution payload, its output, and (for the history methods) one read and one write of each
  // full-resolution history plane. Scratch buffers are not counted: they are the implementation's choice.
  const std::size_t full = std::size_t(W) * H * 4, low = full / (std::size_t(k) * k);
  std::size_t b = 4 * full + C * low + C * full;  // depth + N, payload in, payload out
  switch (o.method) {
    case Method::Spatial: break;
    case Method::Temporal: b += 2 * full + full + 2 * (2 * full) + C * full; break;  // motion, id; prev z/id r+w; history read
    case Method::Herzog: b += 2 * full + full + 2 * (2 * full) + C * full + 2 * full; break;  // + h_w r+w, motion, id
    case Method::Drobot:
      if (o.drobot_mode == DrobotMode::Refresh)
        b += 2 * full + 2 * full + C * full;  // motion, prev depth r+w, history read
      else
        b += 2 * full / (std::size_t(k) * k) + 2 * (C + 2) * low;  // motion at samples, low-res history r+w
      break;
  }
  return b;
}

Expected<Image*> Upsampler::process(const Image& gbuffer, const Image& low, std::span<const std::string> channels,
                                    bool cut, FrameStats* stats_out, const FrameNames& names) {
  const auto t0 = std::chrono::steady_clock::now();
  const Options& o = options_;
  State& s = *state_;
  FrameStats stats;
  FrameContext f;

  // --- validate ---
  const std::string& gname = names.gbuffer;
  const std::string& lname = names.input;
  auto need = [&](const char* c) -> const float* {
    return gbuffer.plane(c);
  };
  for (const std::string& layer : gbuffer_layers(o)) {
    const auto have = gbuffer.layer_channels(layer);
    bool ok = false;
    if (layer == "id") ok = gbuffer.uint_plane("id") != nullptr;
    else if (layer == "depth") ok = need("depth.Z") != nullptr;
    else if (layer == "N") ok = need("N.X") && need("N.Y") && need("N.Z");
    else if (layer == "albedo") ok = need("albedo.R") && need("albedo.G") && need("albedo.B");
    else ok = need("motion.X") && need("motion.Y");
    if (!ok)
      return Error::input(gname, "no layer '" + layer + "' (have: " + join(gbuffer.channel_names()) +
                                     "); render the G-buffer with render-gbuffer --outputs gbuffer" +
                                     (layer == "id" ? " (or pass --no-ids)" : ""));
  }
  if (channels.empty()) return Error::input(lname, "no payload channels selected");
  if (channels.size() > 16)
    return Error::usage("at most 16 payload channels per run (" + std::to_string(channels.size()) +
                        " selected): split --layer over several runs");
  for (const auto& c : channels)
    if (!low.plane(c)) return Error::input(lname, "no float channel '" + c + "' (have: " + join(low.channel_names()) + ")");
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
  int sx = 0, sy = 0;
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
    sx = i % k;
    sy = i / k;
  } else {
    return Error::input(lname, "no temporal:jitter or temporal:jitterIndex in the header (docs/conventions.md, Jitter)");
  }
  if (o.demodulate) {
    demod_->albedo.assign(channels.size(), nullptr);
    int n = 0;
    for (std::size_t c = 0; c < channels.size(); ++c) {
      const std::string a = albedo_channel(channels[c]);
      if (a.empty()) continue;
      demod_->albedo[c] = gbuffer.plane(a);
      if (!demod_->albedo[c])
        return Error::input(gname, "no channel '" + a + "' for --demodulate (have: " + join(gbuffer.channel_names()) +
                                       "); render the G-buffer with render-gbuffer --outputs gbuffer");
      ++n;
    }
    if (n == 0)
      return Error::usage("--demodulate needs colour channels (R, G, B or LAYER.R, .G, .B) in the payload; "
                          "the selected ones are " + join(std::vector<std::string>(channels.begin(), channels.end())));
  }
  f.W = gbuffer.width();
  f.H = gbuffer.height();
  f.lw = low.width();
  f.lh = low.height();
  f.grid = {k, sx, sy};
  f.C = int(channels.size());
  for (const auto& c : channels) f.low.push_back(low.plane(c));
  f.z = gbuffer.plane("depth.Z");
  f.nx = gbuffer.plane("N.X");
  f.ny = gbuffer.plane("N.Y");
  f.nz = gbuffer.plane("N.Z");
  f.mx = gbuffer.plane("motion.X");
  f.my = gbuffer.plane("motion.Y");
  f.id = gbuffer.uint_plane("id");
  const FrameMetadata& gm = gbuffer.metadata();
  std::optional<float> near_clip = gm.near_clip ? gm.near_clip : lm.near_clip;
  std::optional<float> far_clip = gm.far_clip ? gm.far_clip : lm.far_clip;
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
  // Scalar "norm" of the payload for the temporal gradient (seed 000 3.5.1): luminance of R,G,B triples.
  f.luma.assign(f.C, 0.0f);
  {
    float total = 0;
    for (int c = 0; c < f.C; ++c) {
      const std::string& n = channels[c];
      const char last = n.empty() ? ' ' : n.back();
      const bool colour = n.size() == 1 || (n.size() > 2 && n[n.size() - 2] == '.');
      f.luma[c] = !colour ? 1.0f : last == 'R' ? 0.2126f : last == 'G' ? 0.7152f : last == 'B' ? 0.0722f : 1.0f;
      total += f.luma[c];
    }
    for (auto& w : f.luma) w /= total;
  }

  // --- state ---
  const bool cut_flag = cut || (gm.camera_cut && *gm.camera_cut) || (lm.camera_cut && *lm.camera_cut);
  std::vector<std::string> chans(channels.begin(), channels.end());
  if (s.W != f.W || s.H != f.H || s.k != k || s.channels != chans) {
    s.have_history = false;
    s.W = f.W;
    s.H = f.H;
    s.k = k;
    s.C = f.C;
    s.lw = f.lw;
    s.lh = f.lh;
    s.channels = chans;
    for (auto& r : s.result) {
      r = Image(f.W, f.H);
      for (const auto& c : chans) r.add_channel(c);
    }
  }
  if (cut_flag) s.have_history = false;
  stats.history_reset = !s.have_history;
  s.cur = 1 - s.cur;
  s.cols.build(f.W, f.lw, k, sx);
  s.rows.build(f.H, f.lh, k, sy);

  std::size_t nonfinite = 0;
  for (int c = 0; c < f.C; ++c) nonfinite += count_non_finite({f.low[c], std::size_t(f.lw) * f.lh});
  stats.non_finite_input = nonfinite;
  if (o.demodulate) {
    // Low-resolution sample (x, y) lies on full-resolution pixel (k x + sx, k y + sy) (docs/conventions.md).
    demod_->low.resize(f.C);
    for (int c = 0; c < f.C; ++c) {
      if (!demod_->albedo[c]) continue;
      auto& dst = demod_->low[c];
      dst.resize(std::size_t(f.lw) * f.lh);
      const float* src = f.low[c];
      const float* alb = demod_->albedo[c];
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
  gather_low_geometry(s, f);

  switch (o.method) {
    case Method::Spatial: run_spatial(s, f, o, stats); break;
    case Method::Temporal: run_temporal(s, f, o, stats); break;
    case Method::Herzog: run_herzog(s, f, o, stats); break;
    case Method::Drobot: run_drobot(s, f, o, stats); break;
  }
  // Histories need the previous depth and id.
  if (o.method != Method::Spatial) {
    s.prev_z.assign(f.z, f.z + std::size_t(f.W) * f.H);
    if (f.id) s.prev_id.assign(f.id, f.id + std::size_t(f.W) * f.H);
  }
  s.have_history = true;
  s.prev_sx = sx;
  s.prev_sy = sy;

  Image* result = &s.result[s.cur];
  if (o.demodulate) {
    // Multiply by the full-resolution albedo into a separate image: s.result stays the (demodulated) history.
    Image& out = demod_->out;
    if (out.width() != f.W || out.height() != f.H) out = Image(f.W, f.H);
    for (const auto& name : result->channel_names()) {
      const float* src = result->plane(name);
      float* dst = out.add_channel(name);
      const float* alb = nullptr;
      for (int c = 0; c < f.C; ++c)
        if (channels[c] == name) alb = demod_->albedo[c];
      parallel_rows(f.H, [&](int y0, int y1) {
        const std::size_t b = std::size_t(y0) * f.W, e = std::size_t(y1) * f.W;
        if (!alb) {
          std::copy(src + b, src + e, dst + b);
          return;
        }
        for (std::size_t i = b; i < e; ++i) dst[i] = alb[i] >= kMinAlbedo ? src[i] * alb[i] : src[i];
      });
    }
    result = &out;
  }
  if (m > 1) {
    // Seed 000 section 4: the upsampled result at m x m the display resolution, box-downsampled.
    const int ow = f.W / m, oh = f.H / m;
    if (s.aa.width() != ow || s.aa.height() != oh) s.aa = Image(ow, oh);
    for (const auto& name : result->channel_names()) {
      const float* src = result->plane(name);
      float* dst = s.aa.add_channel(name);
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
    result = &s.aa;
  }
  result->metadata() = FrameMetadata{};
  stats.compute_ms = std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count();
  if (stats_out) *stats_out = stats;
  return result;
}

}  // namespace temporal::upsample
