// `didyk`: seed 004 (Didyk et al. 2010) temporal upsampling. Section numbers refer to the paper;
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
#include "didyk_options.h"
#include "method_common.h"
#include "temporal/core/color.h"
#include "temporal/core/fast_math.h"
#include "temporal/core/isa.h"
#include "temporal/core/parallel.h"
#include "temporal/morph/blur_pyramid.h"
#include "temporal/morph/gpu_methods.h"
#include "temporal/morph/grid_warp.h"
#include "temporal/morph/methods.h"

#include <algorithm>
#include <cmath>
#include <limits>

namespace temporal::morph {
namespace {

using namespace detail;

// The per-pixel passes, one copy per instruction set (temporal/core/isa.h). v3 and v4 contract the polynomial of
// fast_math::pow and the compensation's products into FMAs (v2 has none): v2 differs from them in the last bits
// (tests/core/isa_test.cpp); v3 and v4 are bit-identical.
#define TEMPORAL_ISA_FILE "didyk_kernels.inc"
#include "temporal/core/isa_copies.inc"

void display_span_copy(const float* l, float* v, float inv_gamma, std::size_t i0, std::size_t i1) {
  TEMPORAL_ISA_CALL(copy, return copy::display_span(l, v, inv_gamma, i0, i1))
}
void compensate_span_copy(const float* o, const float* v, const float* l, const float* bs, float* top, float* lowlin,
                          float gamma, bool compensate, std::size_t i0, std::size_t i1) {
  TEMPORAL_ISA_CALL(copy, return copy::compensate_span(o, v, l, bs, top, lowlin, gamma, compensate, i0, i1))
}

class Didyk final : public MorphMethod {
 public:
  Didyk(const MorphOptions& options, const DidykOptions& didyk) : options_(options), didyk_(didyk) {
    didyk_.grid.pixels_per_degree = options.pixels_per_degree;
    didyk_.grid.fps = options.fps;
  }

  void run(const Image& color, const Image* gbuffer, const Image*, std::vector<Image>& out, MorphTimings& t) override {
    using clock = std::chrono::steady_clock;
    const std::size_t np = color.pixel_count();
    planes_.resize(kPlanes);
    for (auto& p : planes_) p.resize(np);
    const float* depth = gbuffer->plane("depth.Z");
    // --- flow: snapped grid and damped vertex motion (section 6).
    auto t0 = clock::now();
    grid_builder_.build(gbuffer->plane("motion.X"), gbuffer->plane("motion.Y"), depth, color.width(), color.height(),
                        didyk_.grid, grid_);
    t.flow_ms = ms_since(t0);
    // --- morph (part 1): warped vertices, distortion and blur strength of each in-between slot.
    t0 = clock::now();
    blur_strengths(int(out.size()));
    t.morph_ms = ms_since(t0);
    // --- blur: low-pass of the rendered frame in display values, compensation (section 5.1).
    t0 = clock::now();
    compensate(color, out[0]);
    t.blur_ms = ms_since(t0);
    if (options_.debug_layers) debug_rendered_slot(out[0]);
    // --- morph (part 2): rasterise the sharp frame and its low-pass through the warped grid.
    t0 = clock::now();
    for (std::size_t k = 1; k < out.size(); ++k) draw_slot(color, depth, k, out[k]);
    t.morph_ms += ms_since(t0);
  }

 private:
  // Scratch planes: 0-2 display values v, 3-5 low-pass L (display values), 6-8 adjusted low-pass in linear
  // light, 9 blur sum B on the source, 10 blur strength, 11 distortion (of the slot being drawn).
  enum { kV = 0, kL = 3, kLowLin = 6, kBSum = 9, kBlur = 10, kDist = 11, kPlanes = 12 };
  float* P(int i) { return planes_[std::size_t(i)].data(); }

  // Per slot k >= 1: extrapolated vertices, per-vertex distortion and blur strength b_k; blur_sum_ = sum_k b_k.
  void blur_strengths(int n) {
    const std::size_t nv = std::size_t(grid_.vertex_count());
    const auto slots = static_cast<std::size_t>(n);
    tx_.resize(slots);
    ty_.resize(slots);
    vblur_.resize(slots);
    vdist_.resize(slots);
    blur_sum_.assign(nv, 0.0f);
    for (std::size_t k = 1; k < slots; ++k) {
      extrapolate_vertices(grid_, float(k) / float(n), tx_[k], ty_[k]);
      cell_distortion(grid_, tx_[k], ty_[k], cells_);
      cells_to_vertices(grid_, cells_, vdist_[k]);
      auto& b = vblur_[k];
      b.resize(nv);
      for (std::size_t v = 0; v < nv; ++v) {
        b[v] = std::max(didyk_.min_blur, smoothstep(didyk_.distortion_low, didyk_.distortion_high, vdist_[k][v]));
        blur_sum_[v] += b[v];
      }
    }
  }

  // Display values, their low-pass, the blur sum B on the source grid, and the compensated rendered frame
  // (slot 0) with the low-frequency layer of the in-between frames (section 5.1).
  void compensate(const Image& color, Image& o0) {
    const int w = color.width(), h = color.height();
    const std::size_t np = color.pixel_count();
    const float gamma = options_.gamma, inv_gamma = 1.0f / gamma;
    for (int c = 0; c < 3; ++c) {
      float* v = P(kV + c);
      const float* l = color.plane(kRGB[c]);
      parallel_chunks(np, [&](std::size_t i0, std::size_t i1) { display_span_copy(l, v, inv_gamma, i0, i1); });
    }
    const float* vplanes[3] = {P(kV), P(kV + 1), P(kV + 2)};
    float* lplanes[3] = {P(kL), P(kL + 1), P(kL + 2)};
    pyramid_.build(vplanes, w, h, std::max(1, int(std::ceil(didyk_.blur_level))));
    pyramid_.reconstruct(didyk_.blur_level, lplanes);
    // N_eff - 1 = sum_k b_k at every source pixel: the per-vertex sums drawn on the unwarped (snapped) grid.
    const float* attrs[1] = {blur_sum_.data()};
    float* attr_out[1] = {P(kBSum)};
    GridRaster r;
    r.attributes = attrs;
    r.attr_target = attr_out;
    r.cull_zero_attributes = true;  // B is zero wherever no in-between frame is blurred
    rasterizer_.draw(grid_, grid_.x, grid_.y, r);
    // Section 5.1 per channel, in linear light where possible: with o = v^g and Lg = L^g the rendered frame's
    // (L + H')^g is (1 + B) o - B Lg, so only L^g needs a power. Branch-free: the loop vectorises.
    const bool comp = didyk_.compensate;
    for (int c = 0; c < 3; ++c) {
      const float* o = color.plane(kRGB[c]);
      const float* v = P(kV + c);
      const float* l = P(kL + c);
      const float* bs = P(kBSum);
      float* top = o0.plane(kRGB[c]);
      float* lowlin = P(kLowLin + c);
      parallel_chunks(np, [&](std::size_t i0, std::size_t i1) {
        compensate_span_copy(o, v, l, bs, top, lowlin, gamma, comp, i0, i1);
      });
    }
    if (!options_.debug_layers) return;
    float* dbgH = o0.plane("debug.H");
    float* dbgHp = o0.plane("debug.Hprime");
    parallel_chunks(np, [&](std::size_t i0, std::size_t i1) {
      for (std::size_t i = i0; i < i1; ++i) {
        float hv[3], hp[3];
        for (int c = 0; c < 3; ++c) {
          const float l = planes_[std::size_t(kL + c)][i];
          hv[c] = planes_[std::size_t(kV + c)][i] - l;
          hp[c] = fast_math::pow(std::clamp(o0.plane(kRGB[c])[i], 0.0f, 1.0f), inv_gamma) - l;
        }
        dbgH[i] = luminance(hv[0], hv[1], hv[2]);
        dbgHp[i] = luminance(hp[0], hp[1], hp[2]);
      }
    });
  }

  // debug.grid (the snapped grid), debug.distortion (0) and debug.blur (the blur sum B) of the rendered slot.
  void debug_rendered_slot(Image& o0) {
    const std::size_t np = o0.pixel_count();
    std::fill(o0.plane("debug.grid"), o0.plane("debug.grid") + np, 0.0f);
    draw_grid_lines(grid_, grid_.x, grid_.y, o0.plane("debug.grid"));
    std::fill(o0.plane("debug.distortion"), o0.plane("debug.distortion") + np, 0.0f);
    std::copy(P(kBSum), P(kBSum) + np, o0.plane("debug.blur"));  // slot 0: the blur sum B the compensation used
  }

  // Slot k: the sharp frame and its low-pass through the warped grid, blended by the blur strength.
  void draw_slot(const Image& color, const float* depth, std::size_t k, Image& o) {
    const bool debug = options_.debug_layers;
    const std::size_t np = color.pixel_count();
    float* sharp[3] = {o.plane("R"), o.plane("G"), o.plane("B")};
    const float* sources[6] = {color.plane("R"), color.plane("G"), color.plane("B"), P(kLowLin), P(kLowLin + 1),
                               P(kLowLin + 2)};
    const float* attrs[2] = {vblur_[k].data(), vdist_[k].data()};
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
    rasterizer_.draw(grid_, tx_[k], ty_[k], r);
    if (!debug) return;
    float* g = o.plane("debug.grid");
    std::fill(g, g + np, 0.0f);
    draw_grid_lines(grid_, tx_[k], ty_[k], g);
    std::copy(P(kDist), P(kDist) + np, o.plane("debug.distortion"));
    std::copy(P(kBlur), P(kBlur) + np, o.plane("debug.blur"));
    std::fill(o.plane("debug.H"), o.plane("debug.H") + np, 0.0f);
    std::fill(o.plane("debug.Hprime"), o.plane("debug.Hprime") + np, 0.0f);
  }

  MorphOptions options_;
  DidykOptions didyk_;  // with the eye-tracking limit of options_
  GridBuilder grid_builder_;
  GridRasterizer rasterizer_;
  BlurPyramid pyramid_;
  SnappedGrid grid_;
  std::vector<std::vector<float>> planes_;              // full-resolution scratch planes (enum above)
  std::vector<std::vector<float>> tx_, ty_, vblur_, vdist_;  // per slot, per vertex
  std::vector<float> cells_, blur_sum_;                 // per cell; per vertex
};

}  // namespace

const MethodEntry& didyk_method() {
  static const MethodEntry entry{
      .info = {.name = "didyk",
               .summary = "seed 004: snapped grid morph along the motion, selective blur, high-frequency compensation",
               .latency_frames = 0},
      .make_options = OptionsOf<DidykOptions>::make,
      .layers = [](const MorphOptions&) { return std::vector<LayerNeed>{{"motion"}, {"depth"}}; },
      // The C++ implementation is the reference of record; the GPU one (didyk_gpu.cpp) runs the same steps as GLSL
      // compute kernels, within the tolerances of docs/gpu.md.
      .implementations = {{kCpuDevice,
                           [](const MorphOptions& o) -> std::unique_ptr<MorphMethod> {
                             return std::make_unique<Didyk>(o, method_options<DidykOptions>(o.per_method, "didyk"));
                           }},
                          {kGpuDevice, make_didyk_method_gpu}},
  };
  return entry;
}

}  // namespace temporal::morph
