// FXAA 3.11 "PC quality" (fxaa.cpp) as two GLSL compute kernels: the perceptual luma and validity planes, then the
// per-pixel edge test, edge-end search and final fetch, statement for statement as fxaa.cpp (the search uses the
// gpu stage's GLSL bilinear fetch, reproject::bilinear's taps and weights).
#include "gpu_filter.h"
#include "temporal/phlm/fxaa.h"
#include "temporal/phlm/gpu_filters.h"

namespace temporal::phlm {
namespace {

// src (binding 0): the C colour planes; work (1): luma (plane 0) and validity (1, 0/1); outb (2): the C output
// planes, then debug.edge.
constexpr const char* kFxaaDecl = R"(
uniform uint u_n;
uniform int u_channels;
uniform bool u_debug;
uniform float u_subpix, u_edge_threshold, u_edge_threshold_min;
const float kSteps[12] = float[12](1.0, 1.0, 1.0, 1.0, 1.0, 1.5, 2.0, 2.0, 2.0, 2.0, 4.0, 8.0);
)";

constexpr const char* kLumaMain = R"(
void main() {
  ivec2 p;
  uint i;
  const bool inside = pixel_index(p, i);
  count_begin();
  if (inside) {
    bool ok = true;
    for (int c = 0; c < u_channels; ++c) ok = ok && is_sample(src[uint(c) * u_n + i]);
    // temporal/core/color.h luminance; sqrt of the value clamped to [0, 1]; 0 for a non-finite pixel.
    const float l = u_channels == 3 ? 0.2126 * src[i] + 0.7152 * src[u_n + i] + 0.0722 * src[2u * u_n + i] : src[i];
    work[i] = ok ? sqrt(clamp(l, 0.0, 1.0)) : 0.0;
    work[u_n + i] = ok ? 1.0 : 0.0;
    count_add(1, !ok);
  }
  count_end();
}
)";

constexpr const char* kFxaaMain = R"(
float at(int x, int y) {
  return work[uint(clamp(y, 0, u_size.y - 1)) * uint(u_size.x) + uint(clamp(x, 0, u_size.x - 1))];
}
float sample_luma(float fx, float fy) {
  const Taps b = reproject_bilinear(vec2(fx, fy));
  return REPROJECT_GATHER(work, 0u, b);
}
bool valid_at(uint q) { return work[u_n + q] > 0.0; }

void main() {
  ivec2 p;
  uint i;
  const bool inside = pixel_index(p, i);
  count_begin();
  if (inside) {
    const int px = p.x, py = p.y, w = u_size.x, h = u_size.y;
    bool edge = false;
    if (!valid_at(i)) {
      // No sample here: the mean of the finite 4-neighbours, 0 when there is none.
      const ivec2 nb[4] = ivec2[4](ivec2(-1, 0), ivec2(1, 0), ivec2(0, -1), ivec2(0, 1));
      for (int c = 0; c < u_channels; ++c) {
        float sum = 0.0;
        int n = 0;
        for (int k = 0; k < 4; ++k) {
          const int qx = px + nb[k].x, qy = py + nb[k].y;
          if (qx < 0 || qy < 0 || qx >= w || qy >= h) continue;
          const uint q = uint(qy) * uint(w) + uint(qx);
          if (!valid_at(q)) continue;
          sum += src[uint(c) * u_n + q];
          ++n;
        }
        outb[uint(c) * u_n + i] = n > 0 ? sum / float(n) : 0.0;
      }
    } else {
      const float lumaM = at(px, py);
      float lumaN = at(px, py - 1), lumaS = at(px, py + 1);
      const float lumaW = at(px - 1, py), lumaE = at(px + 1, py);
      const float rangeMax = max(max(max(max(lumaS, lumaE), lumaN), lumaW), lumaM);
      const float rangeMin = min(min(min(min(lumaS, lumaE), lumaN), lumaW), lumaM);
      const float range = rangeMax - rangeMin;
      if (range < max(u_edge_threshold_min, rangeMax * u_edge_threshold)) {
        for (int c = 0; c < u_channels; ++c) outb[uint(c) * u_n + i] = src[uint(c) * u_n + i];
      } else {
        edge = true;
        const float lumaNW = at(px - 1, py - 1), lumaSE = at(px + 1, py + 1);
        const float lumaNE = at(px + 1, py - 1), lumaSW = at(px - 1, py + 1);
        const float lumaNS = lumaN + lumaS, lumaWE = lumaW + lumaE;
        const float subpixRcpRange = 1.0 / range;
        const float subpixNSWE = lumaNS + lumaWE;
        const float edgeHorz1 = -2.0 * lumaM + lumaNS;
        const float edgeVert1 = -2.0 * lumaM + lumaWE;
        const float lumaNESE = lumaNE + lumaSE, lumaNWNE = lumaNW + lumaNE;
        const float edgeHorz2 = -2.0 * lumaE + lumaNESE;
        const float edgeVert2 = -2.0 * lumaN + lumaNWNE;
        const float lumaNWSW = lumaNW + lumaSW, lumaSWSE = lumaSW + lumaSE;
        const float edgeHorz4 = abs(edgeHorz1) * 2.0 + abs(edgeHorz2);
        const float edgeVert4 = abs(edgeVert1) * 2.0 + abs(edgeVert2);
        const float edgeHorz3 = -2.0 * lumaW + lumaNWSW;
        const float edgeVert3 = -2.0 * lumaS + lumaSWSE;
        const float edgeHorz = abs(edgeHorz3) + edgeHorz4;
        const float edgeVert = abs(edgeVert3) + edgeVert4;
        const float subpixNWSWNESE = lumaNWSW + lumaNESE;
        const bool horzSpan = edgeHorz >= edgeVert;
        float lengthSign = 1.0;
        const float subpixA = subpixNSWE * 2.0 + subpixNWSWNESE;
        if (!horzSpan) {
          lumaN = lumaW;
          lumaS = lumaE;
        }
        const float subpixB = subpixA * (1.0 / 12.0) - lumaM;
        const float gradientN = lumaN - lumaM, gradientS = lumaS - lumaM;
        float lumaNN = lumaN + lumaM;
        const float lumaSS = lumaS + lumaM;
        const bool pairN = abs(gradientN) >= abs(gradientS);
        const float gradient = max(abs(gradientN), abs(gradientS));
        if (pairN) lengthSign = -lengthSign;
        const float subpixC = clamp(abs(subpixB) * subpixRcpRange, 0.0, 1.0);
        float posBx = float(px), posBy = float(py);
        const float offx = horzSpan ? 1.0 : 0.0, offy = horzSpan ? 0.0 : 1.0;
        if (!horzSpan) posBx += lengthSign * 0.5;
        if (horzSpan) posBy += lengthSign * 0.5;
        float posNx = posBx - offx * kSteps[0], posNy = posBy - offy * kSteps[0];
        float posPx = posBx + offx * kSteps[0], posPy = posBy + offy * kSteps[0];
        const float subpixD = -2.0 * subpixC + 3.0;
        float lumaEndN = sample_luma(posNx, posNy);
        const float subpixE = subpixC * subpixC;
        float lumaEndP = sample_luma(posPx, posPy);
        if (!pairN) lumaNN = lumaSS;
        const float gradientScaled = gradient * (1.0 / 4.0);
        const float lumaMM = lumaM - lumaNN * 0.5;
        const float subpixF = subpixD * subpixE;
        const bool lumaMLTZero = lumaMM < 0.0;
        lumaEndN -= lumaNN * 0.5;
        lumaEndP -= lumaNN * 0.5;
        bool doneN = abs(lumaEndN) >= gradientScaled;
        bool doneP = abs(lumaEndP) >= gradientScaled;
        if (!doneN) { posNx -= offx * kSteps[1]; posNy -= offy * kSteps[1]; }
        if (!doneP) { posPx += offx * kSteps[1]; posPy += offy * kSteps[1]; }
        for (int step = 2; step < 12 && !(doneN && doneP); ++step) {
          if (!doneN) lumaEndN = sample_luma(posNx, posNy) - lumaNN * 0.5;
          if (!doneP) lumaEndP = sample_luma(posPx, posPy) - lumaNN * 0.5;
          doneN = abs(lumaEndN) >= gradientScaled;
          doneP = abs(lumaEndP) >= gradientScaled;
          if (!doneN) { posNx -= offx * kSteps[step]; posNy -= offy * kSteps[step]; }
          if (!doneP) { posPx += offx * kSteps[step]; posPy += offy * kSteps[step]; }
        }
        const float dstN = horzSpan ? float(px) - posNx : float(py) - posNy;
        const float dstP = horzSpan ? posPx - float(px) : posPy - float(py);
        const bool goodSpanN = (lumaEndN < 0.0) != lumaMLTZero;
        const bool goodSpanP = (lumaEndP < 0.0) != lumaMLTZero;
        const float spanLength = dstP + dstN;
        const float spanLengthRcp = 1.0 / spanLength;
        const bool directionN = dstN < dstP;
        const float dst = min(dstN, dstP);
        const bool goodSpan = directionN ? goodSpanN : goodSpanP;
        const float subpixG = subpixF * subpixF;
        const float pixelOffset = dst * (-spanLengthRcp) + 0.5;
        const float subpixH = subpixG * u_subpix;
        const float pixelOffsetGood = goodSpan ? pixelOffset : 0.0;
        const float pixelOffsetSubpix = max(pixelOffsetGood, subpixH);
        float fx = float(px), fy = float(py);
        if (!horzSpan) fx += pixelOffsetSubpix * lengthSign;
        if (horzSpan) fy += pixelOffsetSubpix * lengthSign;
        // Final bilinear fetch; non-finite neighbours would poison it, so fall back to the pixel itself.
        const Taps b = reproject_bilinear(vec2(fx, fy));
        const bool taps_ok = valid_at(uint(b.q[0])) && valid_at(uint(b.q[1])) && valid_at(uint(b.q[2])) &&
                             valid_at(uint(b.q[3]));
        for (int c = 0; c < u_channels; ++c)
          outb[uint(c) * u_n + i] = taps_ok ? REPROJECT_GATHER(src, uint(c) * u_n, b) : src[uint(c) * u_n + i];
      }
    }
    if (u_debug) outb[uint(u_channels) * u_n + i] = edge ? 1.0 : 0.0;
    count_add(0, edge);
  }
  count_end();
}
)";

class FxaaFilterGpu final : public detail::GpuFilter {
 public:
  FxaaFilterGpu(std::shared_ptr<gpu::Context> ctx, FxaaParams params, gpu::Program luma, gpu::Program fxaa,
                gpu::ImageBuffer counters)
      : GpuFilter(std::move(ctx), std::move(counters)), params_(params), luma_(std::move(luma)),
        fxaa_(std::move(fxaa)) {}

  Status process(const FilterInput& in, Image& output, FilterStats* stats) override {
    if (Status s = validate_filter_input(in); !s) return s;
    const int C = int(in.channels.size());
    const int w = in.color->width(), h = in.color->height();
    if (src_.width() != w || src_.height() != h || src_.planes() != C)
      if (Status s = gpu::ImageBuffer::create_all(ctx_, {{&src_, w, h, C}, {&work_, w, h, 2}, {&out_, w, h, C + 1}});
          !s)
        return s;
    if (Status s = upload_colour(in, src_, false); !s) return s;
    if (Status s = counters_.clear(0, 1); !s) return s;
    src_.bind(0);
    work_.bind(1);
    out_.bind(2);
    auto dispatch = [&]() -> Status {
      for (const gpu::Program* program : {&luma_, &fxaa_}) {
        if (Status s = program->use(); !s) return s;
        program->set("u_n", std::uint32_t(src_.pixel_count()));
        program->set("u_channels", C);
        program->set("u_debug", int(in.debug));
        program->set("u_subpix", params_.subpix);
        program->set("u_edge_threshold", params_.edge_threshold);
        program->set("u_edge_threshold_min", params_.edge_threshold_min);
        if (Status s = program->dispatch(w, h); !s) return s;
      }
      return Status::ok();
    };
    if (Status s = timed(dispatch); !s) return s;
    // Colour read, luma and validity written and read, the output written (+ debug).
    timing_.bytes_moved = double(src_.pixel_count()) * 4.0 * (C + 4 + C + (in.debug ? 1 : 0));
    static const char* const kDebugNames[1] = {"debug.edge"};
    if (Status s = download_output(in, output, out_, C, kDebugNames); !s) return s;
    if (stats) {
      std::uint32_t counts[4] = {};
      if (Status s = counters_.download(0, counts); !s) return s;
      *stats = {};
      stats->clamped = counts[0];
      stats->non_finite = counts[1];
    }
    return Status::ok();
  }
  Image saved_state() const override { return {}; }
  Status set_state(const Image& state, int channels) override {
    return FxaaFilter(params_).set_state(state, channels);  // the C++ filter's usage error
  }

 private:
  FxaaParams params_;
  gpu::Program luma_, fxaa_;
  gpu::ImageBuffer src_, work_, out_;
};

}  // namespace

Expected<std::unique_ptr<FrameFilter>> make_fxaa_filter_gpu(std::shared_ptr<gpu::Context> context,
                                                           FxaaParams params) {
  if (Status s = gpu::Context::ensure(context); !s) return s.error();
  const std::string decl =
      gpu::glsl::storage(0, "src") + gpu::glsl::storage(1, "work") + gpu::glsl::storage(2, "outb");
  auto luma = gpu::Program::compile(context, "fxaa luma", {gpu::glsl::prelude(), decl, kFxaaDecl, kLumaMain});
  if (!luma) return luma.error();
  auto fxaa = gpu::Program::compile(context, "fxaa",
                                    {gpu::glsl::prelude(), decl, kFxaaDecl, gpu::glsl::reproject(), kFxaaMain});
  if (!fxaa) return fxaa.error();
  auto counters = gpu::ImageBuffer::create(context, 4, 1, 1);
  if (!counters) return counters.error();
  return std::unique_ptr<FrameFilter>(
      new FxaaFilterGpu(std::move(context), params, std::move(*luma), std::move(*fxaa), std::move(*counters)));
}

}  // namespace temporal::phlm
