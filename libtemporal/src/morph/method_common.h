// What the method sources of the morph stage share (not installed).
#pragma once

#include <chrono>

namespace temporal::morph::detail {

inline constexpr const char* kRGB[3] = {"R", "G", "B"};

inline double ms_since(std::chrono::steady_clock::time_point t0) {
  return std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count();
}

}  // namespace temporal::morph::detail
