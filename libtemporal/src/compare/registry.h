// The entries of compare's metric registry (temporal/compare/comparison.h), one function per metric source
// file. Private to the metrics stage.
#pragma once

#include "temporal/compare/comparison.h"

namespace temporal {

MetricDefinition psnr_rgb_metric();  // metric_psnr.cpp
MetricDefinition psnr_y_metric();    // metric_psnr.cpp
MetricDefinition ssim_metric();      // metric_ssim.cpp
MetricDefinition flicker_metric();   // metric_flicker.cpp
MetricDefinition flip_metric();      // metric_flip.cpp
MetricDefinition psnr_latency_metric();  // metric_psnr_latency.cpp

}  // namespace temporal
