// Regions of compare --regions motion (temporal/compare/comparison.h, docs/compare.md "Regions"): the per-pixel
// classification from the G-buffer and the reference, and the per-region and pooled summaries.
#include "temporal/compare/comparison.h"

#include "temporal/core/reproject.h"

#include <algorithm>
#include <cmath>
#include <limits>

namespace temporal {

const char* region_name(int region) {
  switch (region) {
    case kRegionStatic: return "static";
    case kRegionMoving: return "moving";
    case kRegionDisoccluded: return "disoccluded";
    default: break;
  }
  return "all";
}

void classify_regions(const RegionInputs& in, const RegionOptions& options, std::span<std::uint16_t> still,
                      std::span<std::uint8_t> labels) {
  const std::size_t n = std::size_t(in.width) * std::size_t(in.height);
  if (!in.has_previous) {  // no history anywhere: what a method sees at its first frame or after a cut
    std::fill_n(labels.begin(), n, std::uint8_t(kRegionDisoccluded));
    std::fill_n(still.begin(), n, std::uint16_t(0));
    return;
  }
  // History hit or miss by the reprojection module's rules (off screen, depth/id test), the very test the methods
  // and the flicker metric use: warp a plane of ones, NaN where the fetch misses.
  reproject::Frames fr;
  fr.width = in.width;
  fr.height = in.height;
  fr.motion_x = in.motion_x;
  fr.motion_y = in.motion_y;
  if (in.depth && in.previous_depth) {
    reproject::expect_depth(fr, in.depth, in.warped_depth);
    fr.id = in.id;
    fr.prev_z = in.previous_depth;
    fr.prev_id = in.previous_id;
  }
  std::vector<float> ones(n, 1.0f), hit(n);
  const float* previous[] = {ones.data()};
  float* out[] = {hit.data()};
  reproject::warp_planes(fr, previous, out);
  const int needed = std::max(1, options.static_frames);
  for (std::size_t i = 0; i < n; ++i) {
    if (std::isnan(hit[i])) {
      labels[i] = kRegionDisoccluded;
      still[i] = 0;
      continue;
    }
    const bool zero_motion = std::fabs(in.motion_x[i]) < kStaticMotion && std::fabs(in.motion_y[i]) < kStaticMotion;
    // NaN luminance (a non-finite reference pixel) compares false: never unchanged.
    const bool unchanged = std::fabs(double(in.reference_y[i]) - double(in.previous_reference_y[i])) <=
                           options.static_tolerance;
    still[i] = zero_motion && unchanged ? std::uint16_t(std::min<int>(still[i] + 1, 65535)) : std::uint16_t(0);
    labels[i] = still[i] >= needed ? kRegionStatic : kRegionMoving;
  }
}

std::vector<double> region_series(const SequenceReport& sequence, std::string_view metric, int region) {
  if (region == kAllRegions) return metric_series(sequence, metric);
  std::vector<double> v;
  v.reserve(sequence.frames.size());
  for (const auto& f : sequence.frames) {
    const MetricSample* s = f.sample(metric);
    v.push_back(s && f.has_regions ? s->regions[std::size_t(region)] : kNoValue);
  }
  return v;
}

std::vector<double> region_weights(const SequenceReport& sequence, int region) {
  std::vector<double> w;
  w.reserve(sequence.frames.size());
  for (const auto& f : sequence.frames)
    w.push_back(region == kAllRegions ? double(f.valid_pixels)
                                      : f.has_regions ? double(f.region_pixels[std::size_t(region)]) : 0.0);
  return w;
}

double region_share(const SequenceReport& sequence, int region) {
  double part = 0.0, all = 0.0;
  for (const auto& f : sequence.frames) {
    all += double(f.valid_pixels);
    part += region == kAllRegions ? double(f.valid_pixels) : double(f.region_pixels[std::size_t(region)]);
  }
  return all > 0.0 ? part / all : kNoValue;
}

MeanInterval pooled_summary(const SequenceReport& sequence, std::string_view metric, int region,
                            const BootstrapOptions& options) {
  return bootstrap_pooled_psnr(region_series(sequence, metric, region), region_weights(sequence, region), options);
}

MeanInterval pooled_difference(const SequenceReport& a, const SequenceReport& b, std::string_view metric, int region,
                               const BootstrapOptions& options) {
  return bootstrap_pooled_psnr_difference(region_series(a, metric, region), region_weights(a, region),
                                          region_series(b, metric, region), region_weights(b, region), options);
}

}  // namespace temporal
