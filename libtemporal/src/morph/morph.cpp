// Seed 004 (Didyk et al. 2010) temporal upsampling and its baselines. Section numbers refer to the paper;
// docs/morph-120hz.md lists the choices the paper leaves open.
//
// Order of operations for one rendered frame n (factor N):
//   flow  - G-buffer motion -> snapped grid (max-pyramid of the flow discontinuity, section 6), vertex motion
//           damped by the eye-tracking limit (section 6);
//   morph - for each in-between slot k: vertices extrapolated to t = k/N, cell distortion -> blur strength b_k
//           (smooth-step, section 5.1 "Selective Blur");
//   blur  - rendered frame to display values v = lin^(1/g), low-pass L from the 3-tap binomial pyramid read
//           with tri-cubic reconstruction, compensation (section 5.1 "Gamma Correction" and the dynamic-range
//           rules) with N_eff = 1 + sum_k b_k at each source pixel (b_k rasterised back onto the source grid);
//   morph - for each slot k the sharp frame and its (range-adjusted) low-pass are rasterised through the
//           warped grid with the depth test, and mixed by the rasterised blur strength in linear light.
// The low-pass is computed on the rendered frame and warped with the same grid (rather than blurring each
// warped frame): for a piecewise-affine warp the two agree up to the local scale change, and this way the
// energy balance of the compensation holds exactly along each motion trajectory, the one the eye follows.
#include "temporal/morph/morph.h"

#include "fast_pow.h"
#include "temporal/core/color.h"
#include "temporal/core/parallel.h"

#include <algorithm>
#include <atomic>
#include <bit>
#include <chrono>
#include <cmath>
#include <limits>
#include <numbers>

namespace temporal {

using morph_detail::fast_pow;

Expected<MorphMethod> parse_morph_method(const std::string& name) {
  if (name == "didyk") return MorphMethod::Didyk;
  if (name == "repeat") return MorphMethod::Repeat;
  if (name == "blend") return MorphMethod::Blend;
  if (name == "warp") return MorphMethod::Warp;
  return Error::usage("unknown method '" + name + "': use didyk, repeat, blend or warp");
}

const char* morph_method_name(MorphMethod method) {
  switch (method) {
    case MorphMethod::Didyk: return "didyk";
    case MorphMethod::Repeat: return "repeat";
    case MorphMethod::Blend: return "blend";
    case MorphMethod::Warp: return "warp";
  }
  return "?";
}

float compensated_high_frequency(float high, float low, float frames, float gamma) {
  // Section 5.1: N (H + L)^g = (L + H')^g + (N - 1) L^g.
  const double v = double(frames) * std::pow(double(high + low), double(gamma)) -
                   (double(frames) - 1.0) * std::pow(double(low), double(gamma));
  return float(std::pow(std::max(v, 0.0), 1.0 / double(gamma)) - double(low));
}

namespace {

// Section 5.1 on pixels [i0, i1) of one channel, in linear light: o = original (= v^g), v and l = display
// values of the original and its low-pass, bs = blur sum B. Writes the rendered frame's value (L + H')^g and the
// low-frequency layer of the in-between frames, both linear. A free function with local pointers so that GCC
// vectorises it (inside the lambda the stores might alias the captures).
void compensate_span(const float* o, const float* v, const float* l, const float* bs, float* top, float* lowlin,
                     float gamma, bool compensate, std::size_t i0, std::size_t i1) {
  if (!compensate) {
    for (std::size_t i = i0; i < i1; ++i) {
      top[i] = o[i];
      lowlin[i] = fast_pow(l[i], gamma);
    }
    return;
  }
  // Selects only (no short-circuit logic): the loop vectorises.
  for (std::size_t i = i0; i < i1; ++i) {
    const float oi = o[i], B = bs[i];
    const float lg = fast_pow(l[i], gamma);
    const float top_g = (1.0f + B) * oi - B * lg;  // N_eff (H + L)^g - (N_eff - 1) L^g, N_eff = 1 + B
    const float excess_low = ((1.0f + B) * oi - 1.0f) / (B > 0.0f ? B : 1.0f);
    // Rule 2: the enhanced original would exceed the display: show 1, the excess goes to the low layer.
    float t = top_g > 1.0f ? 1.0f : top_g;
    float lo = top_g > 1.0f ? excess_low : lg;
    // No in-between frame is blurred here: nothing to compensate.
    t = B > 0.0f ? t : oi;
    lo = B > 0.0f ? lo : lg;
    // Rule 1: an original darker than its low-pass is kept in every frame; values outside [0, 1] (not
    // display-referred) pass through.
    const bool keep = (v[i] < l[i]) | (oi < 0.0f) | (oi > 1.0f);
    top[i] = keep ? oi : t;
    lowlin[i] = keep ? oi : lo;
  }
}

inline float smoothstep(float lo, float hi, float x) {
  if (hi <= lo) return x >= hi ? 1.0f : 0.0f;
  const float t = std::clamp((x - lo) / (hi - lo), 0.0f, 1.0f);
  return t * t * (3.0f - 2.0f * t);
}

double ms_since(std::chrono::steady_clock::time_point t0) {
  return std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count();
}

constexpr const char* kRGB[3] = {"R", "G", "B"};
constexpr const char* kDebug[5] = {"debug.grid", "debug.distortion", "debug.blur", "debug.H", "debug.Hprime"};

}  // namespace

// The scalar reference of the per-pixel loop in Morpher::run_didyk (which works in linear light).
CompensatedValue compensate_value(float original, float low, float blurred, float gamma) {
  if (!(original >= 0.0f && original <= 1.0f)) return {original, original};
  // Rule 1: an original darker than its low-pass keeps the original in every frame (the blurred frames
  // would otherwise need negative light to compensate the brightening of dark pixels).
  if (original < low) return {original, original};
  if (!(blurred > 0.0f)) return {original, low};
  const double og = std::pow(double(original), double(gamma)), lg = std::pow(double(low), double(gamma));
  const double top_g = (1.0 + blurred) * og - blurred * lg;
  if (top_g <= 1.0) return {float(std::pow(top_g, 1.0 / gamma)), low};
  // Rule 2: the enhanced original would exceed the display's range: show 1 and move the excess energy into
  // the low-frequency layer of the in-between frames: 1 + B low'^g = (1 + B) original^g.
  return {1.0f, float(std::pow(((1.0 + blurred) * og - 1.0) / blurred, 1.0 / gamma))};
}

Morpher::Morpher(MorphOptions options) : options_(std::move(options)) {}

Status Morpher::check(const Image& color, const Image* gbuffer, const Image* next) const {
  if (options_.factor < 2)
    return Error::usage("--factor must be at least 2 (got " + std::to_string(options_.factor) + ")");
  const int c = options_.grid.cell;
  if (c < 2 || c > 32 || (c & (c - 1)) != 0)
    return Error::usage("--grid must be a power of two from 2 to 32 (got " + std::to_string(c) + ")");
  if (!(options_.gamma > 0.0f)) return Error::usage("--gamma must be positive");
  if (!(options_.blur_level >= 0.0f && options_.blur_level <= 8.0f)) return Error::usage("--blur-level must be in [0, 8]");
  for (const char* ch : kRGB)
    if (!color.plane(ch))
      return Error::input({}, std::string("the colour input has no float channel '") + ch +
                                  "': pass an image with R, G, B (render-gbuffer --outputs color)");
  if (color.empty()) return Error::input({}, "the colour input is empty");
  if (options_.method == MorphMethod::Didyk || options_.method == MorphMethod::Warp) {
    if (!gbuffer) return Error::input({}, "this method needs the G-buffer (--gbuffer) with motion and depth");
    if (!gbuffer->plane("motion.X") || !gbuffer->plane("motion.Y"))
      return Error::input({}, "the G-buffer has no 'motion' layer (motion.X, motion.Y): render it with "
                              "render-gbuffer --outputs gbuffer");
    if (!gbuffer->plane("depth.Z"))
      return Error::input({}, "the G-buffer has no 'depth' layer (depth.Z): render it with render-gbuffer --outputs gbuffer");
    if (gbuffer->width() != color.width() || gbuffer->height() != color.height())
      return Error::input({}, "the G-buffer is " + std::to_string(gbuffer->width()) + "x" + std::to_string(gbuffer->height()) +
                                  " but the colour is " + std::to_string(color.width()) + "x" +
                                  std::to_string(color.height()) + ": render both at the same size");
  }
  if (next) {
    for (const char* ch : kRGB)
      if (!next->plane(ch)) return Error::input({}, std::string("the next colour frame has no channel '") + ch + "'");
    if (next->width() != color.width() || next->height() != color.height())
      return Error::input({}, "the next colour frame's size differs from this frame's");
  }
  return Status::ok();
}

Status Morpher::process(const Image& color, const Image* gbuffer, const Image* next, std::vector<Image>& out,
                        MorphTimings* timings) {
  if (Status s = check(color, gbuffer, next); !s) return s;
  const int w = color.width(), h = color.height(), n = options_.factor;
  out.resize(std::size_t(n));
  for (auto& o : out) {
    if (o.width() != w || o.height() != h) o = Image(w, h);
    for (const char* ch : kRGB) o.add_channel(ch);
    if (options_.debug_layers)
      for (const char* ch : kDebug) o.add_channel(ch);
  }
  MorphTimings t;
  const std::size_t np = color.pixel_count();
  const float* src[3] = {color.plane("R"), color.plane("G"), color.plane("B")};
  auto copy_into = [&](Image& o, const float* const* from) {
    for (int c = 0; c < 3; ++c) std::copy(from[c], from[c] + np, o.plane(kRGB[c]));
  };
  const auto t0 = std::chrono::steady_clock::now();
  switch (options_.method) {
    case MorphMethod::Repeat:
      for (auto& o : out) copy_into(o, src);
      t.morph_ms = ms_since(t0);
      break;
    case MorphMethod::Blend: {
      copy_into(out[0], src);
      const float* nxt[3] = {next ? next->plane("R") : src[0], next ? next->plane("G") : src[1],
                             next ? next->plane("B") : src[2]};
      for (int k = 1; k < n; ++k) {
        const float a = float(k) / float(n);
        for (int c = 0; c < 3; ++c) {
          float* d = out[std::size_t(k)].plane(kRGB[c]);
          const float* p = src[c];
          const float* q = nxt[c];
          parallel_chunks(np, [&](std::size_t i0, std::size_t i1) {
            for (std::size_t i = i0; i < i1; ++i) d[i] = (1.0f - a) * p[i] + a * q[i];
          });
        }
      }
      t.morph_ms = ms_since(t0);
      break;
    }
    case MorphMethod::Warp:
      run_warp(color, *gbuffer, out);
      t.morph_ms = ms_since(t0);
      break;
    case MorphMethod::Didyk:
      run_didyk(color, *gbuffer, out, t);
      break;
  }
  if (timings) *timings = t;
  return Status::ok();
}

void Morpher::run_warp(const Image& color, const Image& gbuffer, std::vector<Image>& out) {
  const int w = color.width(), h = color.height(), n = options_.factor;
  const std::size_t np = color.pixel_count();
  const float* src[3] = {color.plane("R"), color.plane("G"), color.plane("B")};
  for (int c = 0; c < 3; ++c) std::copy(src[c], src[c] + np, out[0].plane(kRGB[c]));
  const float* mx = gbuffer.plane("motion.X");
  const float* my = gbuffer.plane("motion.Y");
  const float* depth = gbuffer.plane("depth.Z");
  warp_buffer_.resize(np);
  constexpr std::uint64_t kEmpty = std::numeric_limits<std::uint64_t>::max();
  for (int k = 1; k < n; ++k) {
    const float t = float(k) / float(n);
    std::fill(warp_buffer_.begin(), warp_buffer_.end(), kEmpty);
    // Forward splat of each source pixel centre to p - t * motion. The depth test is an atomic minimum on
    // (depth bits << 32 | source index): positive floats order like their bit patterns, and the index makes
    // the winner among equal depths independent of the thread schedule.
    parallel_rows(h, [&](int y0, int y1) {
      for (int y = y0; y < y1; ++y) {
        for (int x = 0; x < w; ++x) {
          const std::size_t i = std::size_t(y) * std::size_t(w) + std::size_t(x);
          const float fx = float(x) + 0.5f - t * mx[i], fy = float(y) + 0.5f - t * my[i];
          if (!(fx >= 0.0f && fy >= 0.0f && fx < float(w) && fy < float(h))) continue;
          float z = depth[i];
          if (!(z >= 0.0f)) z = std::numeric_limits<float>::max();
          const std::uint64_t key = (std::uint64_t(std::bit_cast<std::uint32_t>(z)) << 32) | std::uint64_t(i);
          const std::size_t q = std::size_t(int(fy)) * std::size_t(w) + std::size_t(int(fx));
          std::atomic_ref<std::uint64_t> slot(warp_buffer_[q]);
          std::uint64_t cur = slot.load(std::memory_order_relaxed);
          while (key < cur && !slot.compare_exchange_weak(cur, key, std::memory_order_relaxed)) {
          }
        }
      }
    });
    Image& o = out[std::size_t(k)];
    float* dst[3] = {o.plane("R"), o.plane("G"), o.plane("B")};
    parallel_chunks(np, [&](std::size_t i0, std::size_t i1) {
      for (std::size_t i = i0; i < i1; ++i) {
        const std::uint64_t key = warp_buffer_[i];
        const bool hole = key == kEmpty;
        const std::size_t s = std::size_t(key & 0xffffffffu);
        for (int c = 0; c < 3; ++c) dst[c][i] = hole ? 0.0f : src[c][s];  // holes stay black: no hole filling
      }
    });
  }
  if (options_.debug_layers)
    for (auto& o : out)
      for (const char* ch : kDebug) std::fill(o.plane(ch), o.plane(ch) + np, 0.0f);
}

void Morpher::run_didyk(const Image& color, const Image& gbuffer, std::vector<Image>& out, MorphTimings& t) {
  using clock = std::chrono::steady_clock;
  const int w = color.width(), h = color.height(), n = options_.factor;
  const std::size_t np = color.pixel_count();
  const float gamma = options_.gamma, inv_gamma = 1.0f / gamma;
  const float* lin[3] = {color.plane("R"), color.plane("G"), color.plane("B")};
  const float* depth = gbuffer.plane("depth.Z");

  // Scratch planes: 0-2 display values v, 3-5 low-pass L (display values), 6-8 adjusted low-pass in linear
  // light, 9 blur sum B on the source, 10 blur strength, 11 distortion (of the slot being drawn).
  enum { kV = 0, kL = 3, kLowLin = 6, kBSum = 9, kBlur = 10, kDist = 11, kPlanes = 12 };
  planes_.resize(kPlanes);
  for (auto& p : planes_) p.resize(np);
  auto P = [&](int i) { return planes_[std::size_t(i)].data(); };

  // --- flow: snapped grid and damped vertex motion (section 6).
  auto t0 = clock::now();
  grid_builder_.build(gbuffer.plane("motion.X"), gbuffer.plane("motion.Y"), depth, w, h, options_.grid, grid_);
  t.flow_ms = ms_since(t0);

  // --- morph (part 1): warped vertices, distortion and blur strength of each in-between slot.
  t0 = clock::now();
  const std::size_t nv = std::size_t(grid_.vertex_count());
  const auto slots = static_cast<std::size_t>(n);
  std::vector<std::vector<float>> tx(slots), ty(slots), vblur(slots), vdist(slots);
  std::vector<float> cells, blur_sum(nv, 0.0f);
  for (int k = 1; k < n; ++k) {
    extrapolate_vertices(grid_, float(k) / float(n), tx[std::size_t(k)], ty[std::size_t(k)]);
    cell_distortion(grid_, tx[std::size_t(k)], ty[std::size_t(k)], cells);
    cells_to_vertices(grid_, cells, vdist[std::size_t(k)]);
    auto& b = vblur[std::size_t(k)];
    b.resize(nv);
    for (std::size_t v = 0; v < nv; ++v) {
      b[v] = std::max(options_.min_blur,
                      smoothstep(options_.distortion_low, options_.distortion_high, vdist[std::size_t(k)][v]));
      blur_sum[v] += b[v];
    }
  }
  t.morph_ms = ms_since(t0);

  // --- blur: low-pass of the rendered frame in display values, compensation (section 5.1).
  t0 = clock::now();
  for (int c = 0; c < 3; ++c) {
    float* v = P(kV + c);
    const float* l = lin[c];
    parallel_chunks(np, [&](std::size_t i0, std::size_t i1) {
      for (std::size_t i = i0; i < i1; ++i) v[i] = fast_pow(std::clamp(l[i], 0.0f, 1.0f), inv_gamma);
    });
  }
  const float* vplanes[3] = {P(kV), P(kV + 1), P(kV + 2)};
  float* lplanes[3] = {P(kL), P(kL + 1), P(kL + 2)};
  pyramid_.build(vplanes, w, h, std::max(1, int(std::ceil(options_.blur_level))));
  pyramid_.reconstruct(options_.blur_level, lplanes);
  // N_eff - 1 = sum_k b_k at every source pixel: the per-vertex sums drawn on the unwarped (snapped) grid.
  {
    const float* attrs[1] = {blur_sum.data()};
    float* attr_out[1] = {P(kBSum)};
    GridRaster r;
    r.attributes = attrs;
    r.attr_target = attr_out;
    r.cull_zero_attributes = true;  // B is zero wherever no in-between frame is blurred
    rasterizer_.draw(grid_, grid_.x, grid_.y, r);
  }
  Image& o0 = out[0];
  const bool comp = options_.compensate;
  // Section 5.1 per channel, in linear light where possible: with o = v^g and Lg = L^g the rendered frame's
  // (L + H')^g is (1 + B) o - B Lg, so only L^g needs a power. Branch-free: the loop vectorises.
  for (int c = 0; c < 3; ++c) {
    const float* o = lin[c];
    const float* v = P(kV + c);
    const float* l = P(kL + c);
    const float* bs = P(kBSum);
    float* top = o0.plane(kRGB[c]);
    float* lowlin = P(kLowLin + c);
    parallel_chunks(np, [&](std::size_t i0, std::size_t i1) { compensate_span(o, v, l, bs, top, lowlin, gamma, comp, i0, i1); });
  }
  const bool debug = options_.debug_layers;
  if (debug) {
    float* dbgH = o0.plane("debug.H");
    float* dbgHp = o0.plane("debug.Hprime");
    parallel_chunks(np, [&](std::size_t i0, std::size_t i1) {
      for (std::size_t i = i0; i < i1; ++i) {
        float hv[3], hp[3];
        for (int c = 0; c < 3; ++c) {
          const float l = planes_[std::size_t(kL + c)][i];
          hv[c] = planes_[std::size_t(kV + c)][i] - l;
          hp[c] = fast_pow(std::clamp(o0.plane(kRGB[c])[i], 0.0f, 1.0f), inv_gamma) - l;
        }
        dbgH[i] = luminance(hv[0], hv[1], hv[2]);
        dbgHp[i] = luminance(hp[0], hp[1], hp[2]);
      }
    });
  }
  t.blur_ms = ms_since(t0);

  if (debug) {
    std::fill(o0.plane("debug.grid"), o0.plane("debug.grid") + np, 0.0f);
    draw_grid_lines(grid_, grid_.x, grid_.y, o0.plane("debug.grid"));
    std::fill(o0.plane("debug.distortion"), o0.plane("debug.distortion") + np, 0.0f);
    std::copy(P(kBSum), P(kBSum) + np, o0.plane("debug.blur"));  // slot 0: the blur sum B the compensation used
  }

  // --- morph (part 2): rasterise the sharp frame and its low-pass through the warped grid.
  t0 = clock::now();
  for (int k = 1; k < n; ++k) {
    Image& o = out[std::size_t(k)];
    float* sharp[3] = {o.plane("R"), o.plane("G"), o.plane("B")};
    const float* sources[6] = {lin[0], lin[1], lin[2], P(kLowLin), P(kLowLin + 1), P(kLowLin + 2)};
    const float* attrs[2] = {vblur[std::size_t(k)].data(), vdist[std::size_t(k)].data()};
    float* attr_out[2] = {P(kBlur), P(kDist)};
    GridRaster r;
    r.source = sources;
    r.target = sharp;
    r.attributes = std::span<const float* const>(attrs, debug ? 2 : 1);  // distortion: debug layer only
    r.attr_target = std::span<float* const>(attr_out, debug ? 2 : 1);
    const float uncovered[2] = {1.0f, 0.0f};  // an uncovered pixel (never with a border-fixed grid): blurred
    r.attr_uncovered = uncovered;
    r.source_depth = depth;
    // Selective blur: each fragment blends the sharp warp towards the warped low-pass by its blur strength,
    // in linear light.
    r.blend_attribute = 0;
    rasterizer_.draw(grid_, tx[std::size_t(k)], ty[std::size_t(k)], r);
    if (debug) {
      float* g = o.plane("debug.grid");
      std::fill(g, g + np, 0.0f);
      draw_grid_lines(grid_, tx[std::size_t(k)], ty[std::size_t(k)], g);
      std::copy(P(kDist), P(kDist) + np, o.plane("debug.distortion"));
      std::copy(P(kBlur), P(kBlur) + np, o.plane("debug.blur"));
      std::fill(o.plane("debug.H"), o.plane("debug.H") + np, 0.0f);
      std::fill(o.plane("debug.Hprime"), o.plane("debug.Hprime") + np, 0.0f);
    }
  }
  t.morph_ms += ms_since(t0);
}

}  // namespace temporal
