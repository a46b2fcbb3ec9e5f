// FXAA 3.11 "PC quality" (Lottes 2011), written from the white paper's description and its published
// constants (quality preset 12: 12 search steps). Pixel coordinates: the centre of pixel (x, y) is (x, y).
#include "temporal/phlm/fxaa.h"

#include "filter_common.h"
#include "temporal/phlm/filters.h"
#include "temporal/phlm/gpu_filters.h"
#include "temporal/core/color.h"
#include "temporal/core/parallel.h"
#include "temporal/core/reproject.h"

#include <algorithm>
#include <utility>
#include <atomic>
#include <cmath>
#include <vector>

namespace temporal::phlm {
namespace {
// Search steps of FXAA_QUALITY__PRESET 12 (FXAA_QUALITY__P0 .. P11).
constexpr float kSteps[12] = {1.0f, 1.0f, 1.0f, 1.0f, 1.0f, 1.5f, 2.0f, 2.0f, 2.0f, 2.0f, 4.0f, 8.0f};

// The luma plane: pixel reads with repeated edges, and bilinear samples for the edge-end search.
struct LumaPlane {
  const float* L;
  int w, h;
  float at(int x, int y) const {
    return L[std::size_t(std::clamp(y, 0, h - 1)) * std::size_t(w) + std::size_t(std::clamp(x, 0, w - 1))];
  }
  float sample(float fx, float fy) const { return reproject::bilinear(fx, fy, w, h)(L); }
};

// The 3x3 lumas around pixel M (FXAA's names: N above, S below, W left, E right).
struct Luma3x3 {
  float M, N, S, W, E, NW, NE, SW, SE;
};

Luma3x3 read_3x3(const LumaPlane& l, int px, int py) {
  return {l.at(px, py),         l.at(px, py - 1),     l.at(px, py + 1),     l.at(px - 1, py),    l.at(px + 1, py),
          l.at(px - 1, py - 1), l.at(px + 1, py - 1), l.at(px - 1, py + 1), l.at(px + 1, py + 1)};
}

// Local contrast test (FXAA's early exit): false when the 4-neighbourhood's luma range is below
// max(edge_threshold_min, edge_threshold * luma_max) and the pixel passes through; `range` is set either way.
bool edge_contrast(const Luma3x3& l, const FxaaParams& p, float& range) {
  const float rangeMax = std::max({l.S, l.E, l.N, l.W, l.M});
  const float rangeMin = std::min({l.S, l.E, l.N, l.W, l.M});
  range = rangeMax - rangeMin;
  return !(range < std::max(p.edge_threshold_min, rangeMax * p.edge_threshold));
}

// Edge orientation from the 3x3 second differences: true for a horizontal edge (the search runs along x).
bool horizontal_span(const Luma3x3& l) {
  const float edgeHorz1 = -2.0f * l.M + (l.N + l.S);
  const float edgeVert1 = -2.0f * l.M + (l.W + l.E);
  const float edgeHorz2 = -2.0f * l.E + (l.NE + l.SE);
  const float edgeVert2 = -2.0f * l.N + (l.NW + l.NE);
  const float edgeHorz4 = std::fabs(edgeHorz1) * 2.0f + std::fabs(edgeHorz2);
  const float edgeVert4 = std::fabs(edgeVert1) * 2.0f + std::fabs(edgeVert2);
  const float edgeHorz3 = -2.0f * l.W + (l.NW + l.SW);
  const float edgeVert3 = -2.0f * l.S + (l.SW + l.SE);
  return std::fabs(edgeHorz3) + edgeHorz4 >= std::fabs(edgeVert3) + edgeVert4;
}

// The sub-pixel aliasing estimate: how far the pixel's luma is from the 3x3 low-pass, relative to the range, shaped
// by FXAA's smooth curve and scaled by fxaaQualitySubpix.
float subpixel_offset(const Luma3x3& l, float range, float subpix) {
  const float subpixRcpRange = 1.0f / range;
  const float subpixA = ((l.N + l.S) + (l.W + l.E)) * 2.0f + ((l.NW + l.SW) + (l.NE + l.SE));
  const float subpixB = subpixA * (1.0f / 12.0f) - l.M;
  const float subpixC = std::clamp(std::fabs(subpixB) * subpixRcpRange, 0.0f, 1.0f);
  const float subpixD = -2.0f * subpixC + 3.0f;
  const float subpixE = subpixC * subpixC;
  const float subpixF = subpixD * subpixE;
  const float subpixG = subpixF * subpixF;
  return subpixG * subpix;
}

// The side of the edge with the steeper gradient: the pair luma (pixel + neighbour across the edge) and the sign of
// the step towards it.
struct EdgeSide {
  float pair_luma;        // lumaNN of FXAA
  float gradient_scaled;  // a quarter of the steeper gradient: the end-of-edge threshold
  float length_sign;      // -1 towards N (or W), +1 towards S (or E)
};

EdgeSide edge_side(const Luma3x3& l, bool horz) {
  const float lumaN = horz ? l.N : l.W, lumaS = horz ? l.S : l.E;
  const float gradientN = lumaN - l.M, gradientS = lumaS - l.M;
  const bool pairN = std::fabs(gradientN) >= std::fabs(gradientS);
  const float gradient = std::max(std::fabs(gradientN), std::fabs(gradientS));
  return {pairN ? lumaN + l.M : lumaS + l.M, gradient * (1.0f / 4.0f), pairN ? -1.0f : 1.0f};
}

// The edge-end search: from half a pixel across the edge, steps along it in both directions (kSteps) until the
// luma leaves the edge's pair average by the scaled gradient; the offset of the final fetch perpendicular to the
// edge when the nearer end shows the edge turning towards this pixel, else 0.
float edge_end_offset(const LumaPlane& luma, int px, int py, bool horz, const EdgeSide& side, float lumaM) {
  float posBx = float(px), posBy = float(py);
  const float offx = horz ? 1.0f : 0.0f, offy = horz ? 0.0f : 1.0f;
  if (!horz) posBx += side.length_sign * 0.5f;
  if (horz) posBy += side.length_sign * 0.5f;
  float posNx = posBx - offx * kSteps[0], posNy = posBy - offy * kSteps[0];
  float posPx = posBx + offx * kSteps[0], posPy = posBy + offy * kSteps[0];
  const float half_pair = side.pair_luma * 0.5f;
  float lumaEndN = luma.sample(posNx, posNy) - half_pair;
  float lumaEndP = luma.sample(posPx, posPy) - half_pair;
  const bool lumaMLTZero = lumaM - half_pair < 0.0f;
  bool doneN = std::fabs(lumaEndN) >= side.gradient_scaled;
  bool doneP = std::fabs(lumaEndP) >= side.gradient_scaled;
  if (!doneN) posNx -= offx * kSteps[1], posNy -= offy * kSteps[1];
  if (!doneP) posPx += offx * kSteps[1], posPy += offy * kSteps[1];
  for (int step = 2; step < 12 && !(doneN && doneP); ++step) {
    if (!doneN) lumaEndN = luma.sample(posNx, posNy) - half_pair;
    if (!doneP) lumaEndP = luma.sample(posPx, posPy) - half_pair;
    doneN = std::fabs(lumaEndN) >= side.gradient_scaled;
    doneP = std::fabs(lumaEndP) >= side.gradient_scaled;
    if (!doneN) posNx -= offx * kSteps[step], posNy -= offy * kSteps[step];
    if (!doneP) posPx += offx * kSteps[step], posPy += offy * kSteps[step];
  }
  const float dstN = horz ? float(px) - posNx : float(py) - posNy;
  const float dstP = horz ? posPx - float(px) : posPy - float(py);
  const bool goodSpanN = (lumaEndN < 0.0f) != lumaMLTZero;
  const bool goodSpanP = (lumaEndP < 0.0f) != lumaMLTZero;
  const float spanLengthRcp = 1.0f / (dstP + dstN);
  const bool goodSpan = dstN < dstP ? goodSpanN : goodSpanP;
  const float pixelOffset = std::min(dstN, dstP) * (-spanLengthRcp) + 0.5f;
  return goodSpan ? pixelOffset : 0.0f;
}

// A NaN/Inf input pixel: the mean of its finite 4-neighbours, 0 when there is none. A non-finite value never
// reaches the output (docs/conventions.md, "Non-finite values").
void fill_non_finite(const float* const y[3], int channels, const std::vector<std::uint8_t>& valid, int px, int py,
                     int w, int h, float* const out[3]) {
  const std::size_t i = std::size_t(py) * std::size_t(w) + std::size_t(px);
  for (int c = 0; c < channels; ++c) {
    float sum = 0.0f;
    int n = 0;
    for (const auto& [dx, dy] : {std::pair{-1, 0}, std::pair{1, 0}, std::pair{0, -1}, std::pair{0, 1}}) {
      const int qx = px + dx, qy = py + dy;
      if (qx < 0 || qy < 0 || qx >= w || qy >= h) continue;
      const std::size_t q = std::size_t(qy) * std::size_t(w) + std::size_t(qx);
      if (!valid[q]) continue;
      sum += y[c][q];
      ++n;
    }
    out[c][i] = n > 0 ? sum / float(n) : 0.0f;
  }
}

}  // namespace

Status fxaa(const FilterInput& in, Image& output, const FxaaParams& params, FilterStats* stats) {
  if (Status s = validate_filter_input(in); !s) return s;
  const int channels = int(in.channels.size());
  const int w = in.color->width(), h = in.color->height();
  std::vector<std::uint8_t> valid;
  const std::size_t non_finite = detail::prepare_frame(in, false, nullptr, valid);
  const float* y[3] = {};
  for (int c = 0; c < channels; ++c) y[c] = in.color->plane(in.channels[std::size_t(c)]);
  // Perceptual luma (see fxaa.h): sqrt of the clamped luminance; a non-finite pixel has luma 0.
  std::vector<float> luma_plane(in.color->pixel_count());
  parallel_rows(h, [&](int y0, int y1) {
    for (std::size_t i = std::size_t(y0) * std::size_t(w); i < std::size_t(y1) * std::size_t(w); ++i) {
      const float l = channels == 3 ? luminance(y[0][i], y[1][i], y[2][i]) : y[0][i];
      luma_plane[i] = valid[i] ? std::sqrt(std::clamp(l, 0.0f, 1.0f)) : 0.0f;
    }
  });
  float* out[3] = {};
  detail::prepare_output(in, output, out);
  float* dbg = in.debug ? output.add_channel("debug.edge") : nullptr;
  const LumaPlane luma{luma_plane.data(), w, h};
  std::atomic<std::size_t> edges{0};

  parallel_rows(h, [&](int y0, int y1) {
    std::size_t local_edges = 0;
    for (int py = y0; py < y1; ++py)
      for (int px = 0; px < w; ++px) {
        const std::size_t i = std::size_t(py) * std::size_t(w) + std::size_t(px);
        if (!valid[i]) {
          fill_non_finite(y, channels, valid, px, py, w, h, out);
          if (dbg) dbg[i] = 0.0f;
          continue;
        }
        const Luma3x3 l = read_3x3(luma, px, py);
        float range = 0.0f;
        if (!edge_contrast(l, params, range)) {  // no edge: the pixel passes through
          for (int c = 0; c < channels; ++c) out[c][i] = y[c][i];
          if (dbg) dbg[i] = 0.0f;
          continue;
        }
        ++local_edges;
        const bool horz = horizontal_span(l);
        const EdgeSide side = edge_side(l, horz);
        const float offset = std::max(edge_end_offset(luma, px, py, horz, side, l.M),
                                      subpixel_offset(l, range, params.subpix));
        float fx = float(px), fy = float(py);
        if (!horz) fx += offset * side.length_sign;
        if (horz) fy += offset * side.length_sign;
        // Final bilinear fetch; non-finite neighbours would poison it, so fall back to the pixel itself.
        const reproject::Bilinear b = reproject::bilinear(fx, fy, w, h);
        const bool taps_ok = valid[b.i00] && valid[b.i10] && valid[b.i01] && valid[b.i11];
        for (int c = 0; c < channels; ++c) out[c][i] = taps_ok ? b(y[c]) : y[c][i];
        if (dbg) dbg[i] = 1.0f;
      }
    edges += local_edges;
  });
  if (stats) {
    *stats = {};
    stats->non_finite = non_finite;
    stats->clamped = edges.load();
  }
  return Status::ok();
}

// --- Registry entry (temporal/phlm/filters.h) ------------------------------------------------------------------

namespace {

// fxaa's parameters on the command line: the fields of FxaaParams (fxaa.h).
struct FxaaOptions : FxaaParams {
  ParamList params() {
    return {
        Param::real("--fxaa-subpix", "sub-pixel aliasing removal (fxaaQualitySubpix)", &subpix, 0.0, 1.0),
        Param::real("--fxaa-edge-threshold", "fxaaQualityEdgeThreshold", &edge_threshold, 0.0, 1.0),
        Param::real("--fxaa-edge-threshold-min", "fxaaQualityEdgeThresholdMin", &edge_threshold_min, 0.0, 1.0),
    };
  }
};

}  // namespace

const MethodEntry& fxaa_method() {
  static const MethodEntry entry{
      .info = {.name = "fxaa", .summary = "weak reference: FXAA 3.11 (Lottes 2011), spatial only"},
      .make_options = OptionsOf<FxaaOptions>::make,
      .layers = [](const FilterOptions&) { return std::vector<LayerNeed>{}; },
      .implementations = {{kCpuDevice, [](const FilterOptions& o) -> std::unique_ptr<FrameFilter> {
                             return std::make_unique<FxaaFilter>(method_options<FxaaOptions>(o.per_method, "fxaa"));
                           }},
                          {kGpuDevice,
                           [](std::shared_ptr<gpu::Context> c,
                              const FilterOptions& o) -> Expected<std::unique_ptr<FrameFilter>> {
                             return make_fxaa_filter_gpu(std::move(c), method_options<FxaaOptions>(o.per_method, "fxaa"));
                           }}},
  };
  return entry;
}

}  // namespace temporal::phlm
