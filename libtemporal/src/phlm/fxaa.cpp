// FXAA 3.11 "PC quality" (Lottes 2011), written from the white paper's description and its published
// constants (quality preset 12: 12 search steps). Pixel coordinates: the centre of pixel (x, y) is (x, y).
#include "temporal/phlm/fxaa.h"

#include "filter_common.h"
#include "temporal/phlm/filters.h"
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
  std::vector<float> luma(in.color->pixel_count());
  parallel_rows(h, [&](int y0, int y1) {
    for (std::size_t i = std::size_t(y0) * std::size_t(w); i < std::size_t(y1) * std::size_t(w); ++i) {
      const float l = channels == 3 ? luminance(y[0][i], y[1][i], y[2][i]) : y[0][i];
      luma[i] = valid[i] ? std::sqrt(std::clamp(l, 0.0f, 1.0f)) : 0.0f;
    }
  });
  float* out[3] = {};
  detail::prepare_output(in, output, out);
  float* dbg = in.debug ? output.add_channel("debug.edge") : nullptr;
  const float* L = luma.data();
  auto at = [&](int x, int yy) {
    return L[std::size_t(std::clamp(yy, 0, h - 1)) * std::size_t(w) + std::size_t(std::clamp(x, 0, w - 1))];
  };
  auto sample_luma = [&](float fx, float fy) { return reproject::bilinear(fx, fy, w, h)(L); };
  std::atomic<std::size_t> edges{0};

  parallel_rows(h, [&](int y0, int y1) {
    std::size_t local_edges = 0;
    for (int py = y0; py < y1; ++py)
      for (int px = 0; px < w; ++px) {
        const std::size_t i = std::size_t(py) * std::size_t(w) + std::size_t(px);
        auto pass_through = [&] {
          for (int c = 0; c < channels; ++c) out[c][i] = y[c][i];
          if (dbg) dbg[i] = 0.0f;
        };
        if (!valid[i]) {
          // No sample here (NaN/Inf input): the mean of the finite 4-neighbours, 0 when there is none. A non-finite
          // value never reaches the output (docs/conventions.md, "Non-finite values").
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
          if (dbg) dbg[i] = 0.0f;
          continue;
        }
        const float lumaM = at(px, py);
        float lumaN = at(px, py - 1), lumaS = at(px, py + 1);
        const float lumaW = at(px - 1, py), lumaE = at(px + 1, py);
        // Local contrast test (early exit).
        const float rangeMax = std::max({lumaS, lumaE, lumaN, lumaW, lumaM});
        const float rangeMin = std::min({lumaS, lumaE, lumaN, lumaW, lumaM});
        const float range = rangeMax - rangeMin;
        if (range < std::max(params.edge_threshold_min, rangeMax * params.edge_threshold)) {
          pass_through();
          continue;
        }
        ++local_edges;
        const float lumaNW = at(px - 1, py - 1), lumaSE = at(px + 1, py + 1);
        const float lumaNE = at(px + 1, py - 1), lumaSW = at(px - 1, py + 1);
        // Edge orientation from second differences.
        const float lumaNS = lumaN + lumaS, lumaWE = lumaW + lumaE;
        const float subpixRcpRange = 1.0f / range;
        const float subpixNSWE = lumaNS + lumaWE;
        const float edgeHorz1 = -2.0f * lumaM + lumaNS;
        const float edgeVert1 = -2.0f * lumaM + lumaWE;
        const float lumaNESE = lumaNE + lumaSE, lumaNWNE = lumaNW + lumaNE;
        const float edgeHorz2 = -2.0f * lumaE + lumaNESE;
        const float edgeVert2 = -2.0f * lumaN + lumaNWNE;
        const float lumaNWSW = lumaNW + lumaSW, lumaSWSE = lumaSW + lumaSE;
        const float edgeHorz4 = std::fabs(edgeHorz1) * 2.0f + std::fabs(edgeHorz2);
        const float edgeVert4 = std::fabs(edgeVert1) * 2.0f + std::fabs(edgeVert2);
        const float edgeHorz3 = -2.0f * lumaW + lumaNWSW;
        const float edgeVert3 = -2.0f * lumaS + lumaSWSE;
        const float edgeHorz = std::fabs(edgeHorz3) + edgeHorz4;
        const float edgeVert = std::fabs(edgeVert3) + edgeVert4;
        const float subpixNWSWNESE = lumaNWSW + lumaNESE;
        const bool horzSpan = edgeHorz >= edgeVert;
        float lengthSign = 1.0f;  // one pixel
        const float subpixA = subpixNSWE * 2.0f + subpixNWSWNESE;
        if (!horzSpan) {
          lumaN = lumaW;
          lumaS = lumaE;
        }
        const float subpixB = subpixA * (1.0f / 12.0f) - lumaM;
        const float gradientN = lumaN - lumaM, gradientS = lumaS - lumaM;
        float lumaNN = lumaN + lumaM;
        const float lumaSS = lumaS + lumaM;
        const bool pairN = std::fabs(gradientN) >= std::fabs(gradientS);
        const float gradient = std::max(std::fabs(gradientN), std::fabs(gradientS));
        if (pairN) lengthSign = -lengthSign;
        const float subpixC = std::clamp(std::fabs(subpixB) * subpixRcpRange, 0.0f, 1.0f);
        // Start half a pixel across the edge, towards the steeper side; search along the edge.
        float posBx = float(px), posBy = float(py);
        const float offx = horzSpan ? 1.0f : 0.0f, offy = horzSpan ? 0.0f : 1.0f;
        if (!horzSpan) posBx += lengthSign * 0.5f;
        if (horzSpan) posBy += lengthSign * 0.5f;
        float posNx = posBx - offx * kSteps[0], posNy = posBy - offy * kSteps[0];
        float posPx = posBx + offx * kSteps[0], posPy = posBy + offy * kSteps[0];
        const float subpixD = -2.0f * subpixC + 3.0f;
        float lumaEndN = sample_luma(posNx, posNy);
        const float subpixE = subpixC * subpixC;
        float lumaEndP = sample_luma(posPx, posPy);
        if (!pairN) lumaNN = lumaSS;
        const float gradientScaled = gradient * (1.0f / 4.0f);
        const float lumaMM = lumaM - lumaNN * 0.5f;
        const float subpixF = subpixD * subpixE;
        const bool lumaMLTZero = lumaMM < 0.0f;
        lumaEndN -= lumaNN * 0.5f;
        lumaEndP -= lumaNN * 0.5f;
        bool doneN = std::fabs(lumaEndN) >= gradientScaled;
        bool doneP = std::fabs(lumaEndP) >= gradientScaled;
        if (!doneN) posNx -= offx * kSteps[1], posNy -= offy * kSteps[1];
        if (!doneP) posPx += offx * kSteps[1], posPy += offy * kSteps[1];
        for (int step = 2; step < 12 && !(doneN && doneP); ++step) {
          if (!doneN) lumaEndN = sample_luma(posNx, posNy) - lumaNN * 0.5f;
          if (!doneP) lumaEndP = sample_luma(posPx, posPy) - lumaNN * 0.5f;
          doneN = std::fabs(lumaEndN) >= gradientScaled;
          doneP = std::fabs(lumaEndP) >= gradientScaled;
          if (!doneN) posNx -= offx * kSteps[step], posNy -= offy * kSteps[step];
          if (!doneP) posPx += offx * kSteps[step], posPy += offy * kSteps[step];
        }
        const float dstN = horzSpan ? float(px) - posNx : float(py) - posNy;
        const float dstP = horzSpan ? posPx - float(px) : posPy - float(py);
        const bool goodSpanN = (lumaEndN < 0.0f) != lumaMLTZero;
        const bool goodSpanP = (lumaEndP < 0.0f) != lumaMLTZero;
        const float spanLength = dstP + dstN;
        const float spanLengthRcp = 1.0f / spanLength;
        const bool directionN = dstN < dstP;
        const float dst = std::min(dstN, dstP);
        const bool goodSpan = directionN ? goodSpanN : goodSpanP;
        const float subpixG = subpixF * subpixF;
        const float pixelOffset = dst * (-spanLengthRcp) + 0.5f;
        const float subpixH = subpixG * params.subpix;
        const float pixelOffsetGood = goodSpan ? pixelOffset : 0.0f;
        const float pixelOffsetSubpix = std::max(pixelOffsetGood, subpixH);
        float fx = float(px), fy = float(py);
        if (!horzSpan) fx += pixelOffsetSubpix * lengthSign;
        if (horzSpan) fy += pixelOffsetSubpix * lengthSign;
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
                           }}},
  };
  return entry;
}

}  // namespace temporal::phlm
