// Registry entry `flicker` (docs/compare.md, "Flicker"): RMS of the difference between the test's and the
// reference's motion-compensated change of luminance (temporal/metrics/flicker.h). The engine provides the two
// changes; there is no value at the first frame and at camera cuts. Error map: error.flicker = |d_t|.
#include "registry.h"

#include "temporal/core/image.h"
#include "temporal/metrics/flicker.h"

namespace temporal {
namespace {

class Flicker final : public FrameMeasure {
 public:
  Status measure(const FrameInputs& in, MetricSample& out) override {
    float* map = in.maps ? in.maps->add_channel("error.flicker") : nullptr;  // 0 where there is no value
    out.values = {kNoValue};
    if (!in.test_change || !in.reference_change) return {};
    const FlickerResult f = flicker(in.test_change, in.reference_change, in.width, in.height, in.valid, in.mask, map);
    out.count = f.pixels;
    if (f.pixels) out.values[0] = f.rms();
    if (in.mask) {
      if (f.pixels_inside) out.inside = f.rms_inside();
      if (f.pixels_outside) out.outside = f.rms_outside();
    }
    if (in.regions)  // RMS over the region's pixels that have a value (none where disoccluded: no history)
      for (std::size_t r = 0; r < kRegionCount; ++r) {
        const FlickerResult p = flicker(in.test_change, in.reference_change, in.width, in.height, in.valid,
                                        in.region_masks[r]);
        if (p.pixels_inside) out.regions[r] = p.rms_inside();
      }
    return {};
  }
};

}  // namespace

MetricDefinition flicker_metric() {
  MetricDefinition d;
  d.name = "flicker";
  d.label = "flicker";
  d.higher_is_better = false;
  d.columns = {{"flicker", ""}};
  d.mask_columns = {"flicker_in", "flicker_out"};
  d.historical_csv = true;
  d.threshold_option = "flicker";
  d.threshold_help = "Exit 3 when a sequence's flicker is above this";
  d.chart = {"-flicker", "Temporal instability per frame{motion}",
             "flicker (RMS luminance-change difference, scene-linear units)", true, 0.0, {}};
  d.table_width = 11;
  d.table_format = "%.5f";  // fixed decimals: a column of flicker values lines up
  d.make = [](const ComparisonSetup&) -> std::unique_ptr<FrameMeasure> { return std::make_unique<Flicker>(); };
  return d;
}

}  // namespace temporal
