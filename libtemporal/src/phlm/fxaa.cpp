// FXAA 3.11 "PC quality" (Lottes 2011), written from the white paper's description and its published
// constants (quality preset 12: 12 search steps). Pixel coordinates: the centre of pixel (x, y) is (x, y).
#include "temporal/phlm/fxaa.h"

#include "filter_common.h"
#include "temporal/phlm/filters.h"
#include "temporal/phlm/gpu_filters.h"
#include "temporal/core/color.h"
#include "temporal/core/isa.h"
#include "temporal/core/parallel.h"
#include "temporal/core/reproject.h"

#include <algorithm>
#include <utility>
#include <atomic>
#include <cmath>
#include <vector>

namespace temporal::phlm {
namespace {
// The kernel copies, one per instruction set (temporal/core/isa.h); v3 and v4 contract the bilinear fetches and the
// edge tests' multiply-adds into FMAs where v2 rounds twice (tests/core/isa_test.cpp bounds the difference).
#define TEMPORAL_ISA_FILE "fxaa_kernels.inc"
#include "temporal/core/isa_copies.inc"
}  // namespace

Status fxaa(const FilterInput& in, Image& output, const FxaaParams& params, FilterStats* stats) {
  if (Status s = validate_filter_input(in); !s) return s;
  const int channels = int(in.channels.size());
  const int w = in.color->width(), h = in.color->height();
  std::vector<std::uint8_t> valid;
  const std::size_t non_finite = detail::prepare_frame(in, false, nullptr, valid);
  const float* y[3] = {};
  for (int c = 0; c < channels; ++c) y[c] = in.color->plane(in.channels[std::size_t(c)]);
  float* out[3] = {};
  detail::prepare_output(in, output, out);
  float* dbg = in.debug ? output.add_channel("debug.edge") : nullptr;
  std::vector<float> luma_plane;
  std::size_t edges = 0;
  TEMPORAL_ISA_CALL(copy, edges = copy::run_fxaa(y, channels, valid, w, h, params, luma_plane, out, dbg))
  if (stats) {
    *stats = {};
    stats->non_finite = non_finite;
    stats->clamped = edges;
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
