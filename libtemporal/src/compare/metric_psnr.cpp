// Registry entries `psnr_rgb` and `psnr_y` (docs/compare.md, "PSNR"): 10 log10(L^2 / MSE) over every compared
// channel, and over luminance. Error maps: error.<channel> = |T_c - R_c| and error.Y = |Y_T - Y_R|.
#include "registry.h"

#include "temporal/core/image.h"
#include "temporal/metrics/metrics.h"

#include <cmath>

namespace temporal {
namespace {

std::string suffix_of(const std::string& name) {
  const auto dot = name.rfind('.');
  return dot == std::string::npos ? name : name.substr(dot + 1);
}

// |a - b| where valid, else 0, into a new error-map channel.
void absolute_error(Image& maps, const std::string& channel, const float* a, const float* b, const std::uint8_t* valid) {
  float* e = maps.add_channel(channel);
  for (std::size_t i = 0; i < maps.pixel_count(); ++i) e[i] = valid[i] ? std::fabs(a[i] - b[i]) : 0.0f;
}

class PsnrRgb final : public FrameMeasure {
 public:
  Status measure(const FrameInputs& in, MetricSample& out) override {
    const auto err = squared_error(in.test, in.reference, in.width, in.height, in.valid, in.mask);
    out.values = {psnr_db(err.all, in.peak), err.all.samples ? err.all.mean() : kNoValue};
    out.count = err.all.samples / std::max<std::size_t>(1, in.test.size());
    if (in.mask) {
      out.inside = psnr_db(err.inside, in.peak);
      out.outside = psnr_db(err.outside, in.peak);
    }
    if (in.regions) out.regions = region_psnr(in.test, in.reference, in);
    if (in.maps)
      for (std::size_t c = 0; c < in.test.size(); ++c)
        absolute_error(*in.maps, "error." + suffix_of(in.channels[c]), in.test[c], in.reference[c], in.valid);
    return {};
  }
};

class PsnrY final : public FrameMeasure {
 public:
  Status measure(const FrameInputs& in, MetricSample& out) override {
    const float* ty = in.test_y;
    const float* ry = in.reference_y;
    const auto err = squared_error({&ty, 1}, {&ry, 1}, in.width, in.height, in.valid, in.mask);
    out.values = {psnr_db(err.all, in.peak)};
    out.count = err.all.samples;
    if (in.mask) {
      out.inside = psnr_db(err.inside, in.peak);
      out.outside = psnr_db(err.outside, in.peak);
    }
    if (in.regions) out.regions = region_psnr({&ty, 1}, {&ry, 1}, in);
    if (in.maps) absolute_error(*in.maps, "error.Y", ty, ry, in.valid);
    return {};
  }
};

}  // namespace

MetricDefinition psnr_rgb_metric() {
  MetricDefinition d;
  d.name = "psnr_rgb";
  d.label = "PSNR";
  d.unit = "dB";
  d.columns = {{"psnr_rgb_db", ""}, {"mse_rgb", ""}};
  d.mask_columns = {"psnr_rgb_in_db", "psnr_rgb_out_db"};
  d.historical_csv = true;
  d.pooled = true;
  d.threshold_option = "psnr";
  d.threshold_help = "Exit 3 when a sequence's PSNR (dB) is below this";
  d.chart = {"", "PSNR ({layer}) per frame", "PSNR (dB)", false, {}, {}};
  d.table_width = 10;
  d.table_format = "%.3f";
  d.make = [](const ComparisonSetup&) -> std::unique_ptr<FrameMeasure> { return std::make_unique<PsnrRgb>(); };
  return d;
}

MetricDefinition psnr_y_metric() {
  MetricDefinition d;
  d.name = "psnr_y";
  d.label = "PSNR-Y";
  d.unit = "dB";
  d.columns = {{"psnr_y_db", ""}};
  d.mask_columns = {"psnr_y_in_db", "psnr_y_out_db"};
  d.historical_csv = true;
  d.pooled = true;
  d.chart = {"-psnr-y", "PSNR of luminance per frame", "PSNR of luminance (dB)", false, {}, {}};
  d.table_width = 10;
  d.table_format = "%.3f";
  d.on_sheet = false;  // the sheet's PSNR line says it
  d.make = [](const ComparisonSetup&) -> std::unique_ptr<FrameMeasure> { return std::make_unique<PsnrY>(); };
  return d;
}

}  // namespace temporal
