// The upsampling variants the benchmark and the golden-check tool run, by index (Google Benchmark's range
// argument): each method once, plus drobot --mode refresh and herzog --lagged-wf.
#pragma once

#include "temporal/upsample/upsample.h"

namespace temporal::test {

inline constexpr int kUpsampleVariants = 6;
inline constexpr const char* kUpsampleVariantNames[kUpsampleVariants] = {
    "spatial", "temporal", "herzog", "drobot", "drobot-refresh", "herzog-lagged-wf"};

inline upsample::Options upsample_variant(int index) {
  upsample::Options o;
  switch (index) {
    case 0: o.method = upsample::Method::Spatial; break;
    case 1: o.method = upsample::Method::Temporal; break;
    case 2: o.method = upsample::Method::Herzog; break;
    case 3: o.method = upsample::Method::Drobot; break;
    case 4: o.method = upsample::Method::Drobot; o.drobot_mode = upsample::DrobotMode::Refresh; break;
    default: o.method = upsample::Method::Herzog; o.lagged_wf = true; break;
  }
  return o;
}

}  // namespace temporal::test
