// Viewing geometry (temporal/core/viewing.h).
#include "temporal/core/viewing.h"

#include <cmath>

namespace temporal {

float pixels_per_degree(float screen_width_m, float distance_m, int pixels_x) {
  const double fov = 2.0 * std::atan(double(screen_width_m) / (2.0 * double(distance_m))) * 180.0 / std::numbers::pi;
  return float(double(pixels_x) / fov);
}

}  // namespace temporal
