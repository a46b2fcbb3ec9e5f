// Registry entry `ssim` (docs/compare.md, "SSIM"): Wang et al. 2004 MSSIM on luminance (temporal/metrics/
// metrics.h). Error map: error.ssim = 1 - SSIM at each window centre, 0 on the border without a full window.
#include "registry.h"

#include "temporal/core/image.h"
#include "temporal/metrics/metrics.h"

namespace temporal {
namespace {

class Ssim final : public FrameMeasure {
 public:
  Status measure(const FrameInputs& in, MetricSample& out) override {
    SsimOptions options;
    options.peak = in.peak;
    float* map = in.maps ? in.maps->add_channel("error.ssim") : nullptr;
    auto s = ssim(in.test_y, in.reference_y, in.width, in.height, in.valid, in.mask, options, map);
    if (!s) return s.error();
    out.values = {s->mean};
    out.count = s->windows;
    if (in.mask) {
      out.inside = s->mean_inside;
      out.outside = s->mean_outside;
    }
    if (in.regions) {
      // Per region: the mean SSIM of the windows centred in the region (as the mask split does). Static and
      // moving by two more passes; disoccluded from what remains of the whole sum.
      double rest_sum = s->mean * double(s->windows);
      std::size_t rest = s->windows;
      for (const int r : {kRegionStatic, kRegionMoving}) {
        auto part = ssim(in.test_y, in.reference_y, in.width, in.height, in.valid, in.region_masks[std::size_t(r)],
                         options);
        if (!part) return part.error();
        out.regions[std::size_t(r)] = part->windows_inside ? part->mean_inside : kNoValue;
        if (part->windows_inside) rest_sum -= part->mean_inside * double(part->windows_inside);
        rest -= part->windows_inside;
      }
      out.regions[kRegionDisoccluded] = rest ? rest_sum / double(rest) : kNoValue;
    }
    return {};
  }
};

}  // namespace

MetricDefinition ssim_metric() {
  MetricDefinition d;
  d.name = "ssim";
  d.label = "SSIM";
  d.columns = {{"ssim", ""}};
  d.mask_columns = {"ssim_in", "ssim_out"};
  d.historical_csv = true;
  d.threshold_option = "ssim";
  d.threshold_help = "Exit 3 when a sequence's SSIM is below this";
  d.chart = {"-ssim", "SSIM of luminance per frame", "SSIM (unitless, 1 = identical)", false, {}, 1.0};
  d.table_width = 9;
  d.table_format = "%.5f";
  d.make = [](const ComparisonSetup&) -> std::unique_ptr<FrameMeasure> { return std::make_unique<Ssim>(); };
  return d;
}

}  // namespace temporal
