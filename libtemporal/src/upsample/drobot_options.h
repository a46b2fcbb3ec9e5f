// drobot's options (seed 002), shared by its C++ implementation (drobot.cpp) and its GLSL one (drobot_gpu.cpp),
// which must read the same fields. Internal (not installed), like method.h.
#pragma once

#include "method.h"

#include "temporal/core/method.h"
#include "temporal/core/params.h"

#include <algorithm>
#include <cstddef>
#include <string>

namespace temporal::upsample {

// drobot's parameters (seed 002; the choices are in docs/upsample-st.md).
struct DrobotOptions {
  std::string mode = "cache";     // cache: the framework of section 7.2; refresh: Figure 7.12
  float normal_power = 32.0f;     // contrastCoef of Listing 7.1
  bool depth_only = false;        // depth weights only in Listing 7.1 (the chapter's console variant)
  float miss_threshold = 0.02f;   // IN_MissThreshold of Listing 7.2 (relative depth)
  float convergence_time = 50.0f; // IN_ConvergenceTime of Listing 7.2
  float max_frames = 0.0f;        // frames in the exponential history; 0 = k * k (the pattern length, Figure 7.6)
  bool cache_point = false;       // point instead of bilinear filtering of the low-resolution cache (Figure 7.5);
                                  // the depth test always uses bilinear depth (Listing 7.2)
  float filter_amp = 200.0f;      // IN_BilateralFilterAmp of Listing 7.3 (per relative depth; not given there)

  bool refresh() const { return mode == "refresh"; }
  ParamList params() {
    return {
        Param::choice("--mode", "cache (the framework of section 7.2) or refresh (Figure 7.12)", &mode,
                      {"cache", "refresh"}),
        Param::real("--normal-power", "contrastCoef of Listing 7.1", &normal_power, 0.0, 1000.0),
        Param::flag_on("--depth-only", "depth weights only in Listing 7.1 (the chapter's console variant)", &depth_only),
        Param::real("--miss-threshold", "IN_MissThreshold of Listing 7.2, relative depth", &miss_threshold, 0.0, 10.0),
        Param::real("--convergence-time", "IN_ConvergenceTime of Listing 7.2", &convergence_time, 1e-3, 1e6),
        Param::real("--max-frames", "frames of the exponential history; 0 = k^2 (the pattern length, Figure 7.6)",
                    &max_frames, 0.0, 1e6),
        Param::flag_on("--cache-point", "point instead of bilinear filtering of the low-resolution cache (Figure 7.5)",
                       &cache_point),
        Param::real("--filter-amp", "IN_BilateralFilterAmp of Listing 7.3, per relative depth difference", &filter_amp,
                    0.0, 1e6),
    };
  }
};

// The run's drobot options (the defaults when the run has none).
const DrobotOptions& drobot_options(const Options& o);

// The bytes of a W x H plane of 4-byte values that cross the memory bus when cache mode's grid reads it: one pixel
// in k (column k x + k/2) of every k-th row (k y + k/2), the motion and the ids (drobot.cpp's cache_grid_row, the
// GLSL cache update), fetched in whole transfers of `transfer` bytes (a CPU's 64-byte cache line, a GPU's 32-byte
// sector). While a transfer holds at least one sample (4 k <= transfer) every transfer of those rows is read, so
// the plane costs 1 / k of its bytes, not the 1 / k^2 its samples fill (k = 4: 5.2 of 21 MB per 1280x1024 plane,
// not 1.3); beyond that, one transfer per sample. Rows start on a transfer boundary (W 4 bytes is a multiple of
// 64 for the suite's widths; plane memory is 64-byte aligned).
inline std::size_t cache_grid_read_bytes(int W, int H, int k, std::size_t transfer) {
  const std::size_t kk = std::size_t(k);
  const std::size_t rows = (std::size_t(H) + kk - 1) / kk, samples = (std::size_t(W) + kk - 1) / kk;
  const std::size_t row_transfers = (std::size_t(W) * 4 + transfer - 1) / transfer;
  return rows * std::min(row_transfers, samples) * transfer;
}

}  // namespace temporal::upsample
