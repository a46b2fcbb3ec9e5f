// Registry entry `psnr_latency` (docs/compare.md, "Latency-aware PSNR"; docs/conventions.md, "Latency"): PSNR of
// RGB against the reference frame at the instant the test frame is actually displayed. A test whose header
// declares `temporal:latencyFrames = L` (frames of its own sequence) shows its frame t at instant t + L, so it
// is judged against reference frame t + L; `psnr_rgb` (frame t against reference frame t) stays the
// latency-free score. Enabled by `compare --latency-aware`.
#include "registry.h"

#include "temporal/metrics/metrics.h"

namespace temporal {
namespace {

class PsnrLatency final : public FrameMeasure {
 public:
  Status measure(const FrameInputs& in, MetricSample& out) override {
    const double latency = double(in.latency_frames);
    if (in.shown_reference.empty()) {  // reference frame t + L is not on disk: no value (the engine warns)
      out.values = {kNoValue, latency};
      return {};
    }
    const auto err = squared_error(in.test, in.shown_reference, in.width, in.height, in.shown_valid, in.mask);
    out.values = {psnr_db(err.all, in.peak), latency};
    out.count = err.all.samples / std::max<std::size_t>(1, in.test.size());
    if (in.mask) {
      out.inside = psnr_db(err.inside, in.peak);
      out.outside = psnr_db(err.outside, in.peak);
    }
    return {};
  }
};

}  // namespace

MetricDefinition psnr_latency_metric() {
  MetricDefinition d;
  d.name = "psnr_latency";
  d.label = "psnr_latency";  // the contact sheet's text for it since it was added (a label of its own would change it)
  d.unit = "dB";
  d.columns = {{"psnr_latency_db", ""}, {"latency_frames", "latency_frames"}};
  d.mask_columns = {"psnr_latency_in_db", "psnr_latency_out_db"};
  d.threshold_option = "psnr-latency";
  d.threshold_help = "Exit 3 when a sequence's latency-aware PSNR (dB) is below this (needs --latency-aware)";
  d.chart = {"-psnr-latency", "PSNR against the frame shown at the display instant ({layer})", "PSNR, latency-aware (dB)",
             true, {}, {}};
  d.table_width = 12;
  d.table_format = "%.3f";
  d.enabled = [](const ComparisonSetup& setup) { return setup.latency_aware; };
  d.enable_hint = "add --latency-aware";
  d.make = [](const ComparisonSetup&) -> std::unique_ptr<FrameMeasure> { return std::make_unique<PsnrLatency>(); };
  return d;
}

}  // namespace temporal
