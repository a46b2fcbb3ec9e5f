#include "reference.h"

#include "temporal/core/color.h"
#include "temporal/core/jitter.h"
#include "temporal/core/reproject.h"
#include "temporal/upsample/drobot.h"
#include "temporal/upsample/history.h"
#include "temporal/upsample/joint_bilateral.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <stdexcept>

namespace temporal::test {
namespace up = temporal::upsample;
namespace rp = temporal::reproject;

namespace {

// The value of a parameter of `o`, read through the stage's parameter list (the way the command line sets it).
double param(const up::Options& o, const std::string& flag) {
  up::Options copy = o;
  for (const Param& p : up::params(copy))
    if (p.flag == flag)
      return std::visit(
          [](auto* v) -> double {
            using T = std::remove_pointer_t<decltype(v)>;
            if constexpr (std::is_arithmetic_v<T>) return double(*v);
            return 0.0;
          },
          p.value);
  throw std::logic_error("no parameter " + flag);
}
std::string text_param(const up::Options& o, const std::string& flag) {
  up::Options copy = o;
  for (const Param& p : up::params(copy))
    if (p.flag == flag) return *std::get<std::string*>(p.value);
  throw std::logic_error("no parameter " + flag);
}

// The history fetch of temporal/core/reproject.h at position (fx, fy) of a w x h previous frame, one pixel at a
// time: off screen -> miss; the four bilinear taps, those outside the image dropped; each tap that is not the same
// surface (depth within the tolerance, equal ids) dropped; the rest renormalised; a miss below kMinHitWeight.
struct Fetch {
  bool hit = false;
  std::size_t q[4] = {0, 0, 0, 0};
  float w[4] = {0, 0, 0, 0};
  float operator()(const float* plane) const {
    return hit ? w[0] * plane[q[0]] + w[1] * plane[q[1]] + w[2] * plane[q[2]] + w[3] * plane[q[3]] : 0.0f;
  }
};
Fetch fetch(float mx, float my, float x, float y, int w, int h, float z, std::uint32_t id, const float* prev_z,
            const std::uint32_t* prev_id, const rp::SurfaceTest& test) {
  Fetch f;
  if (!(std::abs(mx) < 1e6f && std::abs(my) < 1e6f)) return f;  // NaN, Inf, absurd motion
  const float fx = x + mx, fy = y + my;
  if (!rp::on_screen(fx, fy, w, h)) return f;
  const int x0 = int(std::floor(fx)), y0 = int(std::floor(fy));
  const float tx = fx - std::floor(fx), ty = fy - std::floor(fy);
  float sum = 0;
  for (int j = 0; j < 4; ++j) {
    const int tx_ = x0 + (j & 1), ty_ = y0 + (j >> 1);
    float wj = ((j & 1) ? tx : 1 - tx) * ((j >> 1) ? ty : 1 - ty);
    if (tx_ < 0 || ty_ < 0 || tx_ >= w || ty_ >= h) wj = 0;
    const std::size_t q = std::size_t(std::clamp(ty_, 0, h - 1)) * w + std::size_t(std::clamp(tx_, 0, w - 1));
    if (wj > 0 && !rp::same_surface(z, id, prev_z[q], prev_id ? prev_id[q] : id, test)) wj = 0;
    f.q[j] = q;
    f.w[j] = wj;
    sum += wj;
  }
  if (sum < rp::kMinHitWeight) return f;
  for (float& wj : f.w) wj /= sum;
  f.hit = true;
  return f;
}

int floor_div(int a, int b) { return up::JitterGrid::floor_div(a, b); }

}  // namespace

struct PlainUpsampler::Frame {
  int W = 0, H = 0, lw = 0, lh = 0, k = 1, sx = 0, sy = 0, C = 0;
  const float *z, *nx, *ny, *nz, *mx, *my;
  const std::uint32_t* id;
  std::vector<const float*> low;
  std::vector<char> valid;  // per low-resolution sample: payload and geometry finite
  float sigma_d = 1, depth_range = 1;
  std::vector<float> luma;
  std::size_t at(int X, int Y) const { return std::size_t(Y) * W + X; }
  // Full-resolution pixel of low-resolution sample (x, y) of this frame (docs/conventions.md, Jitter).
  std::size_t sample_pixel(int x, int y) const { return at(k * x + sx, k * y + sy); }
  // The four nearest samples N{i} of pixel (X, Y): tap j = (x0 + (j & 1), y0 + (j >> 1)); exists[j] when inside.
  void taps(int X, int Y, int x[4], int y[4], bool exists[4]) const {
    const int x0 = floor_div(X - sx, k), y0 = floor_div(Y - sy, k);
    for (int j = 0; j < 4; ++j) {
      x[j] = x0 + (j & 1);
      y[j] = y0 + (j >> 1);
      exists[j] = x[j] >= 0 && y[j] >= 0 && x[j] < lw && y[j] < lh;
    }
  }
  // Eq. 2's n * d of sample (x, y) for pixel (X, Y); 0 for an invalid sample or NaN geometry.
  float geometric(int X, int Y, int x, int y, float inv_sn2, float inv_sd2) const {
    if (!valid[std::size_t(y) * lw + x]) return 0.0f;
    const std::size_t i = at(X, Y), s = sample_pixel(x, y);
    const float dot = nx[i] * nx[s] + ny[i] * ny[s] + nz[i] * nz[s];
    const float w = up::geometric_weight(dot, z[i] - z[s], inv_sn2, inv_sd2);
    return w >= 0.0f ? w : 0.0f;
  }
};

PlainUpsampler::PlainUpsampler(const up::Options& options) : options_(options), method_(options.method) {}

Image PlainUpsampler::process(const Image& g, const Image& low, const std::vector<std::string>& channels, bool cut) {
  Frame f;
  f.W = g.width();
  f.H = g.height();
  f.lw = low.width();
  f.lh = low.height();
  f.k = *low.metadata().jitter_factor;
  const int index = *low.metadata().jitter_index;
  const glm::ivec2 sub = regular_subpixel(f.k, index);  // docs/conventions.md "Jitter": the dispersed order
  f.sx = sub.x;
  f.sy = sub.y;
  f.C = int(channels.size());
  f.z = g.plane("depth.Z");
  f.nx = g.plane("N.X");
  f.ny = g.plane("N.Y");
  f.nz = g.plane("N.Z");
  f.mx = g.plane("motion.X");
  f.my = g.plane("motion.Y");
  f.id = options_.no_ids ? nullptr : g.uint_plane("id");
  for (const auto& c : channels) f.low.push_back(low.plane(c));
  f.depth_range = *g.metadata().far_clip - *g.metadata().near_clip;
  f.sigma_d = options_.sigma_depth > 0 ? options_.sigma_depth : options_.sigma_depth_fraction * f.depth_range;
  // The gradient's scalar norm (docs/upsample-st.md): Rec. 709 luminance for R, G, B (also as the last letter of a
  // layer, "diffuse.R"), the mean over it and the other layers: weight 1 for each other layer, then all / their sum.
  float luma_total = 0.0f;
  for (const auto& c : channels) {
    const bool rgb_layer = c.size() == 1 || (c.size() > 2 && c[c.size() - 2] == '.');
    const char last = c.back();
    const float w = !rgb_layer ? 1.0f : last == 'R' ? 0.2126f : last == 'G' ? 0.7152f : last == 'B' ? 0.0722f : 1.0f;
    f.luma.push_back(w);
    luma_total += w;
  }
  for (auto& w : f.luma) w /= luma_total;
  f.valid.resize(std::size_t(f.lw) * f.lh);
  for (int y = 0; y < f.lh; ++y)
    for (int x = 0; x < f.lw; ++x) {
      const std::size_t s = f.sample_pixel(x, y);
      bool ok = std::isfinite(f.z[s]) && std::isfinite(f.nx[s]) && std::isfinite(f.ny[s]) && std::isfinite(f.nz[s]);
      // a payload past kMaxSampleMagnitude is no sample either (temporal/core/image.h, docs/conventions.md)
      for (int c = 0; c < f.C; ++c) ok = ok && usable_sample(f.low[c][std::size_t(y) * f.lw + x]);
      f.valid[std::size_t(y) * f.lw + x] = ok;
    }
  if (cut || prev_out_.width() != f.W || prev_out_.height() != f.H) have_history_ = false;
  Image out(f.W, f.H);
  for (const auto& c : channels) out.add_channel(c);
  const std::string mode = method_ == "drobot" ? text_param(options_, "--mode") : "";
  if (method_ == "spatial") spatial(f, out);
  else if (method_ == "temporal") temporal(f, out);
  else if (method_ == "herzog") herzog(f, out);
  else if (method_ == "taau") taau(f, out);
  else if (mode == "refresh") drobot_refresh(f, out);
  else if (method_ == "drobot") drobot_cache(f, out);
  else throw std::logic_error("no plain implementation of method " + method_);
  prev_out_ = out;
  prev_z_.assign(f.z, f.z + std::size_t(f.W) * f.H);
  if (f.id) prev_id_.assign(f.id, f.id + std::size_t(f.W) * f.H);
  have_history_ = true;
  return out;
}

// Seed 000 eq. 1-3: w_s = n d k with the hat image kernel (section 3.1).
void PlainUpsampler::spatial(const Frame& f, Image& out) const {
  const float inv_sn2 = 1.0f / (options_.sigma_normal * options_.sigma_normal), inv_sd2 = 1.0f / (f.sigma_d * f.sigma_d);
  for (int Y = 0; Y < f.H; ++Y)
    for (int X = 0; X < f.W; ++X) {
      int x[4], y[4];
      bool exists[4];
      f.taps(X, Y, x, y, exists);
      double sum[16] = {}, wsum = 0;
      for (int j = 0; j < 4; ++j) {
        if (!exists[j]) continue;
        const float w = f.geometric(X, Y, x[j], y[j], inv_sn2, inv_sd2) *
                        up::hat_kernel(float(X - (f.k * x[j] + f.sx)), float(Y - (f.k * y[j] + f.sy)), f.k);
        if (!(w > 0)) continue;
        wsum += w;
        for (int c = 0; c < f.C; ++c) sum[c] += w * f.low[c][std::size_t(y[j]) * f.lw + x[j]];
      }
      for (int c = 0; c < f.C; ++c)
        out.plane(out.channel_name(std::size_t(c)))[f.at(X, Y)] = wsum > 0 ? float(sum[c] / wsum) : 0.0f;
    }
}

// Seed 000 eq. 4 (w_t binary), holes filled spatially.
void PlainUpsampler::temporal(const Frame& f, Image& out) {
  Image spatial_out = out;
  spatial(f, spatial_out);
  for (int Y = 0; Y < f.H; ++Y)
    for (int X = 0; X < f.W; ++X) {
      const std::size_t i = f.at(X, Y);
      const bool shaded = (X - f.sx) % f.k == 0 && (Y - f.sy) % f.k == 0 && X >= f.sx && Y >= f.sy &&
                          f.valid[std::size_t((Y - f.sy) / f.k) * f.lw + (X - f.sx) / f.k];
      Fetch h;
      if (have_history_)
        h = fetch(f.mx[i], f.my[i], float(X), float(Y), f.W, f.H, f.z[i], f.id ? f.id[i] : 0, prev_z_.data(),
                  f.id ? prev_id_.data() : nullptr, options_.surface_test());
      for (int c = 0; c < f.C; ++c) {
        const std::string& name = out.channel_name(std::size_t(c));
        float v = spatial_out.plane(name)[i];
        if (shaded) v = f.low[c][std::size_t((Y - f.sy) / f.k) * f.lw + (X - f.sx) / f.k];
        else if (h.hit) v = h(prev_out_.plane(name));
        out.plane(name)[i] = v;
      }
    }
}

// Seed 000 sections 3.3-3.5 in three plain passes over whole images (docs/upsample-st.md, herzog).
void PlainUpsampler::herzog(const Frame& f, Image& out) {
  const float gamma = float(param(options_, "--kernel-gamma")), cap = float(param(options_, "--max-kernel-gamma"));
  const float floor_g = float(param(options_, "--min-kernel-gamma"));
  const bool hat = text_param(options_, "--fallback") == "spatial";  // k = hat * eq. 3, else eq. 3 alone
  const float a = param(options_, "--favor-spatial") != 0 ? up::kFavorSpatialA : float(param(options_, "--a"));
  const int gs = int(param(options_, "--gradient-scale"));
  const float mip = float(param(options_, "--gradient-mip-level"));
  const float max_hw = param(options_, "--max-history-weight") > 0 ? float(param(options_, "--max-history-weight"))
                                                                    : 2.0f * float(f.k * f.k);
  const bool lagged = param(options_, "--lagged-wf") != 0;
  const int W = f.W, H = f.H, GW = (W + gs - 1) / gs, GH = (H + gs - 1) / gs;
  const std::size_t N = std::size_t(W) * H, GN = std::size_t(GW) * GH;
  const bool history = have_history_;
  if (!history) {
    hw_.assign(N, 0.0f);
    wf_.assign(GN, 0.0f);
    for (auto& d : dhist_) d.assign(GN, up::kMaxGradient);
  }
  const float inv_sn2 = 1.0f / (options_.sigma_normal * options_.sigma_normal), inv_sd2 = 1.0f / (f.sigma_d * f.sigma_d);
  const float r = float(f.k) * std::sqrt(2.0f);
  // w_f of the previous frame at the motion-compensated position (nearest cell): shapes k, and --lagged-wf's eq. 7.
  auto wf_prev_at = [&](int X, int Y) {
    if (!history) return 0.0f;
    const std::size_t i = f.at(X, Y);
    const float px = (float(X) + 0.5f + f.mx[i]) / float(gs), py = (float(Y) + 0.5f + f.my[i]) / float(gs);
    if (!(px >= 0 && py >= 0 && px < float(GW) && py < float(GH))) return 0.0f;
    return wf_[std::size_t(py) * GW + std::size_t(px)];
  };
  // Pass A: h~, w~ (eq. 6), w~' (full fall-off), the history fetch and the relative gradient averaged per cell.
  std::vector<float> wt(N), wc(N), hwf(N), gsum(GN, 0.0f), gcount(GN, 0.0f);
  std::vector<std::vector<float>> ht(f.C, std::vector<float>(N)), hr(f.C, std::vector<float>(N));
  for (int Y = 0; Y < H; ++Y)
    for (int X = 0; X < W; ++X) {
      const std::size_t i = f.at(X, Y);
      const float fall_off = std::max(floor_g, up::kernel_gamma(gamma, wf_prev_at(X, Y), cap));
      int x[4], y[4];
      bool exists[4];
      f.taps(X, Y, x, y, exists);
      double sum[16] = {}, wsum = 0, wsharp = 0;
      for (int j = 0; j < 4; ++j) {
        if (!exists[j]) continue;
        const float dx = float(X - (f.k * x[j] + f.sx)), dy = float(Y - (f.k * y[j] + f.sy));
        const float dist = std::sqrt(dx * dx + dy * dy);
        const float g = f.geometric(X, Y, x[j], y[j], inv_sn2, inv_sd2);
        const float base = hat ? up::hat_kernel(dx, dy, f.k) : 1.0f;
        const float w = g * base * up::image_kernel(dist, r, fall_off);
        wsharp += g * base * up::image_kernel(dist, r, up::kernel_gamma(gamma, 1.0f, cap));
        if (!(w > 0)) continue;
        wsum += w;
        for (int c = 0; c < f.C; ++c) sum[c] += w * f.low[c][std::size_t(y[j]) * f.lw + x[j]];
      }
      wt[i] = float(wsum);
      wc[i] = float(wsharp);
      for (int c = 0; c < f.C; ++c) ht[c][i] = wsum > 0 ? float(sum[c] / wsum) : 0.0f;
      Fetch h;
      if (history)
        h = fetch(f.mx[i], f.my[i], float(X), float(Y), W, H, f.z[i], f.id ? f.id[i] : 0, prev_z_.data(),
                  f.id ? prev_id_.data() : nullptr, options_.surface_test());
      hwf[i] = h(hw_.data());
      float yc = 0, yp = 0;
      for (int c = 0; c < f.C; ++c) {
        hr[c][i] = h(prev_out_.plane(out.channel_name(std::size_t(c))));
        yc += f.luma[c] * ht[c][i];
        yp += f.luma[c] * hr[c][i];
      }
      float grad = std::clamp(up::relative_gradient(yc, yp), -up::kMaxGradient, up::kMaxGradient);
      if (!(h.hit && wt[i] > 0)) grad = up::kMaxGradient;  // Figure 6
      const std::size_t cell = std::size_t(Y / gs) * GW + X / gs;
      gsum[cell] += grad;
      gcount[cell] += 1;
    }
  // Pass B: the temporal filter with the previous gradients at the cell centre's motion-compensated cell, the box
  // pyramid and its trilinear sample at the mip level (counted at full resolution), eq. 8.
  std::vector<float> filtered(GN), d_new[3];
  for (auto& d : d_new) d.resize(GN);
  for (int gy = 0; gy < GH; ++gy)
    for (int gx = 0; gx < GW; ++gx) {
      const std::size_t cell = std::size_t(gy) * GW + gx;
      const int cx = std::min(W - 1, gx * gs + gs / 2), cy = std::min(H - 1, gy * gs + gs / 2);
      const float px = (float(cx) + 0.5f + f.mx[f.at(cx, cy)]) / float(gs);
      const float py = (float(cy) + 0.5f + f.my[f.at(cx, cy)]) / float(gs);
      const bool in = history && px >= 0 && py >= 0 && px < float(GW) && py < float(GH);
      const std::size_t q = in ? std::size_t(py) * GW + std::size_t(px) : 0;
      const float d0 = gcount[cell] > 0 ? gsum[cell] / gcount[cell] : up::kMaxGradient;
      float d[3];
      for (int t = 0; t < 3; ++t) d[t] = in ? dhist_[t][q] : up::kMaxGradient;
      filtered[cell] = up::filtered_gradient(d0, d[0], d[1], d[2]);
      d_new[0][cell] = d0;
      d_new[1][cell] = d[0];
      d_new[2][cell] = d[1];
    }
  const float rel = std::max(0.0f, mip - std::log2(float(gs)));
  const int l0 = int(std::floor(rel));
  const float frac = rel - float(l0);
  std::vector<std::vector<float>> pyr = {filtered};
  std::vector<int> pw = {GW}, ph = {GH};
  for (int j = 1; j <= l0 + 1; ++j) {
    const int w = std::max(1, (pw.back() + 1) / 2), h = std::max(1, (ph.back() + 1) / 2);
    std::vector<float> level(std::size_t(w) * h);
    const auto& src = pyr.back();
    for (int y = 0; y < h; ++y)
      for (int x = 0; x < w; ++x) {
        auto at = [&](int xx, int yy) {
          return src[std::size_t(std::min(yy, ph.back() - 1)) * pw.back() + std::min(xx, pw.back() - 1)];
        };
        level[std::size_t(y) * w + x] = 0.25f * (at(2 * x, 2 * y) + at(2 * x + 1, 2 * y) + at(2 * x, 2 * y + 1) +
                                                 at(2 * x + 1, 2 * y + 1));
      }
    pyr.push_back(std::move(level));
    pw.push_back(w);
    ph.push_back(h);
  }
  auto sample = [&](int L, int gx, int gy) {  // bilinear, clamp-to-edge, texel centres at integers
    const float sc = float(1 << L);
    const float u = std::clamp((float(gx) + 0.5f) / sc - 0.5f, 0.0f, float(pw[L] - 1));
    const float v = std::clamp((float(gy) + 0.5f) / sc - 0.5f, 0.0f, float(ph[L] - 1));
    const int x0 = int(u), y0 = int(v), x1 = std::min(x0 + 1, pw[L] - 1), y1 = std::min(y0 + 1, ph[L] - 1);
    const float ax = u - float(x0), ay = v - float(y0);
    auto p = [&](int xx, int yy) { return pyr[L][std::size_t(yy) * pw[L] + xx]; };
    return (1 - ay) * ((1 - ax) * p(x0, y0) + ax * p(x1, y0)) + ay * ((1 - ax) * p(x0, y1) + ax * p(x1, y1));
  };
  std::vector<float> wf_new(GN);
  for (int gy = 0; gy < GH; ++gy)
    for (int gx = 0; gx < GW; ++gx) {
      const float g = frac > 0 ? (1 - frac) * sample(l0, gx, gy) + frac * sample(l0 + 1, gx, gy) : sample(l0, gx, gy);
      wf_new[std::size_t(gy) * GW + gx] = up::temporal_weight(g, a);
    }
  // Pass C: eq. 7 and the bounded history-weight update.
  std::vector<float> hw_new(N);
  for (int Y = 0; Y < H; ++Y)
    for (int X = 0; X < W; ++X) {
      const std::size_t i = f.at(X, Y);
      const float w_f = lagged ? wf_prev_at(X, Y) : wf_new[std::size_t(Y / gs) * GW + X / gs];
      hw_new[i] = up::history_weight_update(wc[i], w_f, hwf[i], max_hw);
      for (int c = 0; c < f.C; ++c) {
        const float h = up::history_blend(ht[c][i], wt[i], w_f, hwf[i], hr[c][i]);
        const bool ok = std::isfinite(h);
        out.plane(out.channel_name(std::size_t(c)))[i] = ok ? h : 0.0f;
        if (!ok) hw_new[i] = 0.0f;
      }
    }
  hw_ = std::move(hw_new);
  wf_ = std::move(wf_new);
  for (int t = 0; t < 3; ++t) dhist_[t] = std::move(d_new[t]);
}

namespace {

// Listing 7.1 at pixel (X, Y) of the coarse samples around it. `tap` gives sample j's coarse index and offsets,
// `value(c, s)` its payload, `avail(s)` its availability; the table weight is the bilinear weight of the offset.
struct Coarse {
  int lw, lh, k, s;  // grid: coarse sample x at full-resolution pixel k x + s
  const float *z, *nx, *ny, *nz;  // geometry per coarse sample
  float offset;      // table offset: d + offset pixels from the sample (0.5 for block centres of even k)
};

float listing71(const Coarse& g, int X, int Y, float zi, float ax, float ay, float az, float power, bool normals,
                float range, const float* avail, const float* value) {
  const int x0 = floor_div(X - g.s, g.k), y0 = floor_div(Y - g.s, g.k);
  const float fx = (float(X - g.s - g.k * x0) + g.offset) / float(g.k);
  const float fy = (float(Y - g.s - g.k * y0) + g.offset) / float(g.k);
  double sum = 0, wsum = 0, tsum = 0, fallback = 0;
  for (int j = 0; j < 4; ++j) {
    const int x = x0 + (j & 1), y = y0 + (j >> 1);
    if (x < 0 || y < 0 || x >= g.lw || y >= g.lh) continue;
    const std::size_t s = std::size_t(y) * g.lw + x;
    const float t = ((j & 1) ? fx : 1 - fx) * ((j >> 1) ? fy : 1 - fy);
    const float dot = ax * g.nx[s] + ay * g.ny[s] + az * g.nz[s];
    const float nw = normals ? up::drobot_normal_weight(dot, power) : 1.0f;
    float w = nw * up::drobot_depth_weight((zi - g.z[s]) / range) * avail[s] * t;
    if (!(w >= 0)) w = 0;
    tsum += t;
    fallback += t * value[s];
    if (w > 0) {
      wsum += w;
      sum += w * value[s];
    }
  }
  if (wsum > 0) return float(sum / wsum);
  const double fb = tsum > 0 ? fallback / tsum : 0.0;
  return std::isfinite(fb) ? float(fb) : 0.0f;
}

// One direction of Listing 7.3 (docs/upsample-st.md): taps at +-1.5 and +-3.5 texels read as two-texel means,
// availability-weighted, depth term 1 / (E + amp |dz| / z), side taps scaled by `strength`.
void listing73(const std::vector<float>& src, const std::vector<float>& z, const std::vector<float>& strength,
               const std::vector<float>& avail, int w, int h, bool horizontal, float amp, std::vector<float>& dst,
               std::vector<float>& avail_out) {
  static constexpr int kPair[4][2] = {{-3, -4}, {-1, -2}, {1, 2}, {3, 4}};
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x) {
      const std::size_t i = std::size_t(y) * w + x;
      auto at = [&](const std::vector<float>& p, int o) {
        const int xx = horizontal ? std::clamp(x + o, 0, w - 1) : x, yy = horizontal ? y : std::clamp(y + o, 0, h - 1);
        return p[std::size_t(yy) * w + xx];
      };
      const float s_i = avail[i] > 0 ? strength[i] : 1.0f;
      double sum = up::kDrobotCenterWeight * avail[i] * src[i], wsum = up::kDrobotCenterWeight * avail[i];
      for (int t = 0; t < 4; ++t) {
        const float a0 = at(avail, kPair[t][0]), a1 = at(avail, kPair[t][1]);
        if (a0 + a1 <= 0) continue;
        const float v = (a0 * at(src, kPair[t][0]) + a1 * at(src, kPair[t][1])) / (a0 + a1);
        const float zt = (a0 * at(z, kPair[t][0]) + a1 * at(z, kPair[t][1])) / (a0 + a1);
        const float rel = z[i] > 0 ? zt / z[i] : 0.0f, centre = z[i] > 0 ? 1.0f : 0.0f;
        const float wt = 0.5f * (a0 + a1) * s_i * up::drobot_filter_tap_weight(centre, rel, amp, up::kDrobotTapWeights[t]);
        sum += wt * v;
        wsum += wt;
      }
      dst[i] = wsum > 0 ? float(sum / wsum) : src[i];
      avail_out[i] = wsum > 0 ? 1.0f : 0.0f;
    }
}

}  // namespace

// Seed 002 section 7.2 with the cache at the k x k block centres (docs/upsample-st.md, drobot).
void PlainUpsampler::drobot_cache(const Frame& f, Image& out) {
  const float thr = float(param(options_, "--miss-threshold")), T = float(param(options_, "--convergence-time"));
  const float nmax = param(options_, "--max-frames") > 0 ? float(param(options_, "--max-frames")) : float(f.k * f.k);
  const bool point = param(options_, "--cache-point") != 0;
  const int k = f.k, lw = f.lw, lh = f.lh, C = f.C;
  const std::size_t LN = std::size_t(lw) * lh;
  const bool history = have_history_ && cache_.size() == std::size_t(C + 2) && cache_[0].size() == LN;
  // The block centres' geometry and ids.
  std::vector<float> bz(LN), bnx(LN), bny(LN), bnz(LN);
  std::vector<std::uint32_t> bid(LN, 0);
  std::vector<std::vector<float>> val(C, std::vector<float>(LN));
  std::vector<float> n_new(LN), strength(LN), have(LN);
  for (int y = 0; y < lh; ++y)
    for (int x = 0; x < lw; ++x) {
      const std::size_t j = std::size_t(y) * lw + x, i = f.at(std::min(f.W - 1, k * x + k / 2), std::min(f.H - 1, k * y + k / 2));
      bz[j] = f.z[i];
      bnx[j] = f.nx[i];
      bny[j] = f.ny[i];
      bnz[j] = f.nz[i];
      if (f.id) bid[j] = f.id[i];
      // Listing 7.2: the module's fetch in the cache grid (motion in cache texels), then the cache-miss test on
      // the bilinear depth of the surviving taps.
      float conf = 0, n_prev = 0, hist[16] = {};
      if (history) {
        const Fetch h = fetch(f.mx[i] / float(k), f.my[i] / float(k), float(x), float(y), lw, lh, bz[j], bid[j],
                              cache_[C].data(), f.id ? cache_id_.data() : nullptr, options_.surface_test());
        if (h.hit) {  // Listing 7.2 on the cache's bilinear depth (all four taps, edges repeated)
          const float zc = rp::bilinear(float(x) + f.mx[i] / float(k), float(y) + f.my[i] / float(k), lw, lh)(cache_[C].data());
          conf = up::drobot_cache_confidence(bz[j] > 0 ? (bz[j] - zc) / bz[j] : 1.0f, thr, T, true);
        }
        if (conf > 0) {
          Fetch read = h;
          if (point) {  // the surviving tap with the largest weight
            int best = 0;
            for (int t = 1; t < 4; ++t)
              if (h.w[t] > h.w[best]) best = t;
            for (int t = 0; t < 4; ++t) read.w[t] = t == best ? 1.0f : 0.0f;
          }
          n_prev = read(cache_[C + 1].data());
          for (int c = 0; c < C; ++c) hist[c] = read(cache_[c].data());
        }
      }
      float n1 = 0;
      const float w = up::drobot_convergence_weight(n_prev, conf, nmax, &n1);
      const float zs = f.z[f.sample_pixel(x, y)];
      const bool finite = f.valid[j] != 0;
      const bool valid = finite && bz[j] > 0 && std::abs(zs - bz[j]) <= thr * bz[j];
      const float n = valid ? n1 : n_prev * conf;
      for (int c = 0; c < C; ++c) {
        float v = valid ? up::exponential_history(hist[c], f.low[c][j], w) : hist[c];
        if (n <= 0) v = finite ? f.low[c][j] : 0.0f;
        val[c][j] = v;
      }
      n_new[j] = n;
      have[j] = n > 0 ? 1.0f : 0.0f;
      strength[j] = 1.0f - std::min(1.0f, n / nmax);
    }
  // Listing 7.3, horizontal then vertical; the result is the new cache.
  const float amp = float(param(options_, "--filter-amp"));
  std::vector<float> tmp(LN), avail_h(LN), avail(LN);
  for (int c = 0; c < C; ++c) {
    listing73(val[c], bz, strength, have, lw, lh, true, amp, tmp, avail_h);
    listing73(tmp, bz, strength, avail_h, lw, lh, false, amp, val[c], avail);
  }
  // Listing 7.1 from the block centres.
  const Coarse grid{lw, lh, k, k / 2, bz.data(), bnx.data(), bny.data(), bnz.data(), k % 2 == 0 ? 0.5f : 0.0f};
  const float power = float(param(options_, "--normal-power"));
  const bool normals = param(options_, "--depth-only") == 0;
  for (int Y = 0; Y < f.H; ++Y)
    for (int X = 0; X < f.W; ++X) {
      const std::size_t i = f.at(X, Y);
      for (int c = 0; c < C; ++c)
        out.plane(out.channel_name(std::size_t(c)))[i] =
            listing71(grid, X, Y, f.z[i], f.nx[i], f.ny[i], f.nz[i], power, normals, f.depth_range, avail.data(),
                      val[c].data());
    }
  cache_ = std::move(val);
  cache_.push_back(std::move(bz));
  cache_.push_back(std::move(n_new));
  cache_id_ = std::move(bid);
}

// Figure 7.12: this frame's samples, the history where the cache test passes, Listing 7.1 elsewhere.
void PlainUpsampler::drobot_refresh(const Frame& f, Image& out) {
  const float thr = float(param(options_, "--miss-threshold")), T = float(param(options_, "--convergence-time"));
  const float power = float(param(options_, "--normal-power"));
  const bool normals = param(options_, "--depth-only") == 0;
  std::vector<float> lz(std::size_t(f.lw) * f.lh), lnx(lz.size()), lny(lz.size()), lnz(lz.size()), avail(lz.size());
  for (int y = 0; y < f.lh; ++y)
    for (int x = 0; x < f.lw; ++x) {
      const std::size_t j = std::size_t(y) * f.lw + x, s = f.sample_pixel(x, y);
      lz[j] = f.z[s];
      lnx[j] = f.nx[s];
      lny[j] = f.ny[s];
      lnz[j] = f.nz[s];
      avail[j] = f.valid[j] ? 1.0f : 0.0f;
    }
  // The refresh buffer's samples sit at this frame's jittered positions: the table of Listing 7.1 there (the
  // grid offset s is the sub-pixel; only square patterns sx = sy are handled by Coarse, so use the general form).
  for (int Y = 0; Y < f.H; ++Y)
    for (int X = 0; X < f.W; ++X) {
      const std::size_t i = f.at(X, Y);
      const bool shaded = X >= f.sx && Y >= f.sy && (X - f.sx) % f.k == 0 && (Y - f.sy) % f.k == 0 &&
                          f.valid[std::size_t((Y - f.sy) / f.k) * f.lw + (X - f.sx) / f.k];
      float conf = 0;
      Fetch h;
      if (!shaded && have_history_) {
        h = fetch(f.mx[i], f.my[i], float(X), float(Y), f.W, f.H, f.z[i], f.id ? f.id[i] : 0, prev_z_.data(),
                  f.id ? prev_id_.data() : nullptr, options_.surface_test());
        if (h.hit) {  // Listing 7.2 on the previous frame's bilinear depth (all four taps, edges repeated)
          const float zc = rp::bilinear(float(X) + f.mx[i], float(Y) + f.my[i], f.W, f.H)(prev_z_.data());
          conf = up::drobot_cache_confidence(f.z[i] > 0 ? (f.z[i] - zc) / f.z[i] : 1.0f, thr, T, true);
        }
      }
      for (int c = 0; c < f.C; ++c) {
        const std::string& name = out.channel_name(std::size_t(c));
        // Listing 7.1 over the jittered grid: shift the pixel so that the grid offset is (sx, sy) on both axes.
        const int x0 = floor_div(X - f.sx, f.k), y0 = floor_div(Y - f.sy, f.k);
        const float fx = float(X - f.sx - f.k * x0) / float(f.k), fy = float(Y - f.sy - f.k * y0) / float(f.k);
        double sum = 0, wsum = 0, tsum = 0, fb = 0;
        for (int j = 0; j < 4; ++j) {
          const int x = x0 + (j & 1), y = y0 + (j >> 1);
          if (x < 0 || y < 0 || x >= f.lw || y >= f.lh) continue;
          const std::size_t s = std::size_t(y) * f.lw + x;
          const float t = ((j & 1) ? fx : 1 - fx) * ((j >> 1) ? fy : 1 - fy);
          const float dot = f.nx[i] * lnx[s] + f.ny[i] * lny[s] + f.nz[i] * lnz[s];
          float w = (normals ? up::drobot_normal_weight(dot, power) : 1.0f) *
                    up::drobot_depth_weight((f.z[i] - lz[s]) / f.depth_range) * avail[s] * t;
          if (!(w >= 0)) w = 0;
          tsum += t;
          fb += t * (avail[s] > 0 ? f.low[c][s] : 0.0f);  // a tap that is no sample holds 0 for the fallback
          if (w > 0) {
            wsum += w;
            sum += w * f.low[c][s];
          }
        }
        float v = wsum > 0 ? float(sum / wsum) : (tsum > 0 && std::isfinite(fb / tsum) ? float(fb / tsum) : 0.0f);
        if (shaded) v = f.low[c][std::size_t((Y - f.sy) / f.k) * f.lw + (X - f.sx) / f.k];
        else if (conf > 0) v += (h(prev_out_.plane(name)) - v) * conf;
        out.plane(name)[i] = v;
      }
    }
}

// `taau` (docs/upsample-st.md, "taau"; FSR 2 / UE4 TAAU) one pixel at a time: the fetch, the 3x3 Lanczos-2
// reconstruction, the YCoCg box, the accumulation and the locks, written from the docs' formulas.
void PlainUpsampler::taau(const Frame& f, Image& out) {
  const bool locks = param(options_, "--no-locks") != 0;  // the field behind the inverted flag: true = locks on
  const float box_scale = float(param(options_, "--box-scale"));
  const float luma_change = float(param(options_, "--lock-luma-change"));
  const float motion_acc = float(param(options_, "--motion-accumulation"));
  const bool catmull_rom = text_param(options_, "--history") == "catmull-rom";
  const int W = f.W, H = f.H, k = f.k, C = f.C;
  const std::size_t N = std::size_t(W) * H;
  if (!have_history_) {
    acc_.assign(N, 0.0f);
    lock_.assign(N, 0.0f);
    lock_luma_.assign(N, 0.0f);
  }
  auto lanczos = [](float x2) {  // FSR 2 Lanczos2ApproxSq
    x2 = std::min(x2, 4.0f);
    return (25.0f / 16.0f * (0.4f * x2 - 1) * (0.4f * x2 - 1) - 9.0f / 16.0f) * (0.25f * x2 - 1) * (0.25f * x2 - 1);
  };
  auto to_ycgco = [C](float* v) {
    for (int t = 0; t + 3 <= C; t += 3) rgb_to_ycgco(v[t], v[t + 1], v[t + 2], v[t], v[t + 1], v[t + 2]);
  };
  auto from_ycgco = [C](float* v) {
    for (int t = 0; t + 3 <= C; t += 3) {
      const float y = v[t], cg = v[t + 1], co = v[t + 2];
      ycgco_to_rgb(y, cg, co, v[t], v[t + 1], v[t + 2]);
    }
  };
  // Sample luminance and thin features (FSR 2 ComputeThinFeatureConfidence).
  std::vector<float> luma(std::size_t(f.lw) * f.lh, 0.0f);
  for (int c = 0; c < C; ++c)
    for (std::size_t s = 0; s < luma.size(); ++s) luma[s] += f.luma[c] * (f.valid[s] ? f.low[c][s] : 0.0f);
  auto thin = [&](int x, int y) {
    const float n = luma[std::size_t(y) * f.lw + x];
    bool similar[9] = {};
    similar[4] = true;
    float dmin = std::numeric_limits<float>::max(), dmax = 0;
    for (int j = 0; j < 9; ++j) {
      if (j == 4) continue;
      const int xx = std::clamp(x + j % 3 - 1, 0, f.lw - 1), yy = std::clamp(y + j / 3 - 1, 0, f.lh - 1);
      const float v = luma[std::size_t(yy) * f.lw + xx];
      const float ratio = std::max(v, n) / std::min(v, n);
      if (ratio > 0 && ratio < 1.05f) {
        similar[j] = true;
      } else {
        dmin = std::min(dmin, v);
        dmax = std::max(dmax, v);
      }
    }
    if (!(n > dmax || n < dmin)) return false;
    for (int q : {0, 1, 3, 4})  // top-left corners of the four 2x2 quads that hold the centre
      if (similar[q] && similar[q + 1] && similar[q + 3] && similar[q + 4]) return false;
    return true;
  };
  const float influence = std::min(20.0f, std::pow(float(k * k), 3.0f));
  std::vector<float> acc_new(N), lock_new(N), luma_new(N);
  for (int Y = 0; Y < H; ++Y)
    for (int X = 0; X < W; ++X) {
      const std::size_t i = f.at(X, Y);
      Fetch h;
      if (have_history_)
        h = fetch(f.mx[i], f.my[i], float(X), float(Y), W, H, f.z[i], f.id ? f.id[i] : 0, prev_z_.data(),
                  f.id ? prev_id_.data() : nullptr, options_.surface_test());
      const float vel = std::isfinite(f.mx[i]) && std::isfinite(f.my[i]) ? std::hypot(f.mx[i], f.my[i]) : 0.0f;
      float hv[16], sum[16] = {}, bs[16] = {}, lo[16] = {}, hi[16] = {}, res[16] = {}, rec[16] = {};
      for (int c = 0; c < C; ++c) hv[c] = h(prev_out_.plane(out.channel_name(std::size_t(c))));
      if (h.hit && catmull_rom) {  // Catmull-Rom where the fetch kept all four taps at their bilinear weights
        const float u = float(X) + f.mx[i], v = float(Y) + f.my[i];
        const rp::Bilinear b = rp::bilinear(u, v, W, H);
        const float raw[4] = {b.w00, b.w10, b.w01, b.w11};
        bool full = true;
        for (int j = 0; j < 4; ++j) full = full && std::abs(h.w[j] - raw[j]) <= 1e-5f;
        if (full)
          for (int c = 0; c < C; ++c)
            hv[c] = rp::catmull_rom(u, v, W, H)(prev_out_.plane(out.channel_name(std::size_t(c))));
      }
      to_ycgco(hv);
      float acc = h(acc_.data()), lock = h(lock_.data()), lluma = h(lock_luma_.data());
      // The nearest sample (ties to the right/below) and its 3x3 neighbourhood.
      const int xn = std::clamp(int(std::floor((float(X - f.sx) + 0.5f * float(k)) / float(k))), 0, f.lw - 1);
      const int yn = std::clamp(int(std::floor((float(Y - f.sy) + 0.5f * float(k)) / float(k))), 0, f.lh - 1);
      const float bias = h.hit ? std::min(1.99f, float(k)) : 1.0f;
      const float curve = -2.0f - std::min(1.0f, vel / 50.0f);
      float ws = 0, bw = 0;
      int n = 0;
      std::vector<std::pair<float, std::vector<float>>> box;  // (weight, sample) for the spread about the mean
      for (int ly = yn - 1; ly <= yn + 1; ++ly)
        for (int lx = xn - 1; lx <= xn + 1; ++lx) {
          if (lx < 0 || ly < 0 || lx >= f.lw || ly >= f.lh || !f.valid[std::size_t(ly) * f.lw + lx]) continue;
          const float ox = float(k * lx + f.sx - X) / float(k), oy = float(k * ly + f.sy - Y) / float(k);
          const float d2 = ox * ox + oy * oy;
          const float wl = lanczos(d2 * bias * bias), wb = std::exp(curve * d2);
          float v[16];
          for (int c = 0; c < C; ++c) v[c] = f.low[c][std::size_t(ly) * f.lw + lx];
          to_ycgco(v);
          for (int c = 0; c < C; ++c) {
            sum[c] += wl * v[c];
            bs[c] += wb * v[c];
            lo[c] = n ? std::min(lo[c], v[c]) : v[c];
            hi[c] = n ? std::max(hi[c], v[c]) : v[c];
          }
          ws += wl;
          bw += wb;
          box.push_back({wb, std::vector<float>(v, v + C)});
          ++n;
        }
      float w_new = 0;
      if (n == 0) {
        for (int c = 0; c < C; ++c) res[c] = h.hit ? hv[c] : 0.0f;
        if (!h.hit) acc = 0;
      } else {
        for (int c = 0; c < C; ++c) rec[c] = ws > 1e-3f ? std::clamp(sum[c] / ws, lo[c], hi[c]) : bs[c] / bw;
        if (ws > 1e-3f) w_new = ws / 12.0f;
        if (!h.hit) {
          for (int c = 0; c < C; ++c) res[c] = rec[c];
          acc = w_new;
        } else {
          const float max_acc = 1.0f + (motion_acc - 1.0f) * std::min(1.0f, vel * 10.0f);
          acc = std::min(acc, max_acc);
          const float s = box_scale > 0 ? box_scale : influence + (1 - influence) * std::min(1.0f, vel / 20.0f);
          const float lock_keep = locks ? std::clamp(4.0f * (lock - 1.0f), 0.0f, 1.0f) : 0.0f;
          float keep_min = 1;
          for (int c = 0; c < C; ++c) {
            const float mean = bs[c] / bw;
            double var = 0;
            for (const auto& [wb, v] : box) var += double(wb) * (v[c] - mean) * (v[c] - mean);
            const float sigma = float(std::sqrt(var / bw));
            const float bmin = std::max(lo[c], mean - s * sigma), bmax = std::min(hi[c], mean + s * sigma);
            const float cl = std::clamp(hv[c], bmin, bmax), centre = (bmin + bmax) / 2;
            const float tau = 1e-5f * (1 + std::max(std::abs(lo[c]), std::abs(hi[c])));
            const float keep = std::min(1.0f, (std::abs(cl - centre) + tau) / (std::abs(hv[c] - centre) + tau) + lock_keep);
            hv[c] = cl + keep * (hv[c] - cl);
            keep_min = std::min(keep_min, keep);
          }
          acc = std::min(acc, 0.1f) + keep_min * (acc - std::min(acc, 0.1f));
          const float a = std::max(1e-3f, acc + w_new);
          for (int c = 0; c < C; ++c) res[c] = hv[c] + (rec[c] - hv[c]) * (w_new / a);
          acc = std::min(a, max_acc);
        }
      }
      from_ycgco(res);
      if (locks) {
        if (!h.hit) lock = 0;
        float yr = 0;
        for (int c = 0; c < C; ++c) yr += f.luma[c] * res[c];
        const float m = std::max(std::abs(yr), std::abs(lluma));
        if (lock > 0 && m > 0 && std::abs(yr - lluma) / m > luma_change) lock = 0;
        const bool at_sample = (X - f.sx) % k == 0 && (Y - f.sy) % k == 0 && X >= f.sx && Y >= f.sy &&
                               (X - f.sx) / k < f.lw && (Y - f.sy) / k < f.lh;
        if (at_sample && thin((X - f.sx) / k, (Y - f.sy) / k)) {
          lock = lock > 0 ? 2.0f : 1.0f;
          lluma = luma[std::size_t((Y - f.sy) / k) * f.lw + (X - f.sx) / k];
        }
        lock = std::max(0.0f, lock - w_new / (float(k * k) * 0.74f / 12.0f));
      } else {
        lock = 0;
      }
      bool ok = true;
      for (int c = 0; c < C; ++c) ok = ok && std::isfinite(res[c]);
      for (int c = 0; c < C; ++c) out.plane(out.channel_name(std::size_t(c)))[i] = ok ? res[c] : 0.0f;
      acc_new[i] = ok ? acc : 0.0f;
      lock_new[i] = ok ? lock : 0.0f;
      luma_new[i] = lluma;
    }
  acc_ = std::move(acc_new);
  lock_ = std::move(lock_new);
  lock_luma_ = std::move(luma_new);
}

}  // namespace temporal::test
