// Registry entry `flip` (docs/compare.md, "FLIP"): the mean of the per-pixel FLIP map (temporal/metrics/flip.h)
// and its weighted quartiles as NVIDIA's tool reports them. Measured only with `--flip ldr|hdr`:
//   ldr: LDR-FLIP of the display-encoded frames, i.e. the sRGB OETF of the values clamped to [0, 1]. FLIP
//        linearises its input with the exact inverse, so the clamped linear values are given to it directly
//        (FlipLdrInput::Linear: the same result without the round trip; no 8-bit quantisation).
//   hdr: HDR-FLIP of the scene-linear values (ACES, automatic exposures from each reference frame).
// The compared layer must have three channels (R, G, B) or one (grey: used as R = G = B, as NVIDIA's tool reads
// a one-channel EXR). Error map: error.flip, 0 at invalid pixels.
#include "registry.h"

#include "temporal/core/image.h"

#include <vector>

namespace temporal {
namespace {

class Flip final : public FrameMeasure {
 public:
  explicit Flip(const ComparisonSetup& setup) : mode_(setup.flip), evaluator_([&] {
    FlipOptions o = setup.flip_options;
    o.ldr_input = FlipLdrInput::Linear;
    return o;
  }()) {}

  Status measure(const FrameInputs& in, MetricSample& out) override {
    const std::size_t c = in.test.size();
    if (c != 3 && c != 1)
      return Error::input({}, "FLIP compares colour images: the compared layer has " + std::to_string(c) +
                                  " channels; compare an R,G,B layer (--layer) or a single channel, or drop --flip");
    const std::size_t n = std::size_t(in.width) * std::size_t(in.height);
    auto image = [&](std::span<const float* const> p) {
      return c == 3 ? FlipImage{p[0], p[1], p[2]} : FlipImage{p[0], p[0], p[0]};
    };
    float* map = nullptr;
    if (in.maps) {
      map = in.maps->add_channel("error.flip");
    } else {
      scratch_.resize(n);
      map = scratch_.data();
    }
    if (mode_ == FlipMode::Hdr) {
      auto e = evaluator_.hdr(image(in.test), image(in.reference), in.width, in.height, in.valid, map);
      if (!e) return e.error();
    } else if (auto st = evaluator_.ldr(image(in.test), image(in.reference), in.width, in.height, in.valid, map); !st) {
      return st;
    }
    const FlipStats s = flip_statistics({map, n}, in.valid);
    out.values = {s.mean, s.weighted_median, s.weighted_quartile_1, s.weighted_quartile_3};
    out.count = s.pixels;
    if (in.mask) {
      double sum[2] = {0.0, 0.0};
      std::size_t count[2] = {0, 0};
      for (std::size_t i = 0; i < n; ++i) {
        if (!in.valid[i]) continue;
        const int inside = in.mask[i] > 0.5f ? 0 : 1;
        sum[inside] += map[i];
        ++count[inside];
      }
      out.inside = count[0] ? sum[0] / double(count[0]) : kNoValue;
      out.outside = count[1] ? sum[1] / double(count[1]) : kNoValue;
    }
    if (in.regions) {  // the mean of the FLIP map over each region's valid pixels
      std::array<double, kRegionCount> sum{};
      std::array<std::size_t, kRegionCount> count{};
      for (std::size_t i = 0; i < n; ++i) {
        if (!in.valid[i]) continue;
        sum[in.regions[i]] += map[i];
        ++count[in.regions[i]];
      }
      for (std::size_t r = 0; r < kRegionCount; ++r) out.regions[r] = count[r] ? sum[r] / double(count[r]) : kNoValue;
    }
    return {};
  }

 private:
  FlipMode mode_;
  FlipEvaluator evaluator_;
  std::vector<float> scratch_;
};

}  // namespace

MetricDefinition flip_metric() {
  MetricDefinition d;
  d.name = "flip";
  d.label = "FLIP";
  d.higher_is_better = false;
  d.columns = {{"flip", ""},
               {"flip_weighted_median", "weighted_median"},
               {"flip_weighted_q1", "weighted_quartile_1"},
               {"flip_weighted_q3", "weighted_quartile_3"}};
  d.mask_columns = {"flip_in", "flip_out"};
  d.threshold_option = "flip";
  d.threshold_help = "Exit 3 when a sequence's mean FLIP is above this (needs --flip ldr|hdr)";
  d.chart = {"-flip", "Mean FLIP per frame", "mean FLIP (unitless, 0 = identical, 1 = largest)", false, 0.0, 1.0};
  d.table_width = 9;
  d.table_format = "%.5f";
  d.enabled = [](const ComparisonSetup& setup) { return setup.flip != FlipMode::Off; };
  d.enable_hint = "add --flip ldr or --flip hdr";
  d.make = [](const ComparisonSetup& setup) -> std::unique_ptr<FrameMeasure> { return std::make_unique<Flip>(setup); };
  return d;
}

}  // namespace temporal
