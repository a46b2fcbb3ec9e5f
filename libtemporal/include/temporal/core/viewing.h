// Viewing geometry: how many image pixels span one degree of visual angle for an observer in front of a
// screen. The perceptual parts of the suite need it: morph-120hz's eye-tracking limit (seed 004) converts
// pixel speeds to degrees per second, and FLIP (temporal/metrics/flip.h) sizes its contrast-sensitivity and
// feature filters in degrees.
//
// Geometry: a flat screen `screen_width_m` metres wide showing `pixels_x` pixels across (images 1:1), viewed
// from `distance_m` metres on the axis through the screen centre. Two summaries of it are in use, and they
// differ because a pixel at the edge subtends a smaller angle than one at the centre:
//   - pixels_per_degree():           across the whole width, pixels_x / (2 atan(w / 2d) in degrees);
//   - pixels_per_degree_at_centre(): the local value at the centre, d (pixels_x / w) pi / 180, the smallest
//                                    over the screen (the small-angle form of the same geometry).
// For FLIP's reference condition (0.7 m from a 0.7 m wide 3840-pixel screen) they are 72.27 and 67.02; for
// morph-120hz's default (22" Samsung 2233RZ: 0.473 m, 1680 pixels, 0.6 m) 39.07 and 37.19.
#pragma once

#include <numbers>

namespace temporal {

// Pixels per degree averaged over the screen width: pixels_x / (2 atan(screen_width_m / (2 distance_m))),
// the angle in degrees. morph-120hz derives its eye-tracking limit from it (docs/morph-120hz.md).
float pixels_per_degree(float screen_width_m, float distance_m, int pixels_x);

// Pixels per degree at the screen centre: distance_m * (pixels_x / screen_width_m) * pi / 180. This is FLIP's
// definition (Andersson et al. 2020; NVIDIA's reference code, `calculatePPD`), used for its default viewing
// condition below.
constexpr double pixels_per_degree_at_centre(double screen_width_m, double distance_m, int pixels_x) {
  return distance_m * (double(pixels_x) / screen_width_m) * (std::numbers::pi / 180.0);
}

// FLIP's default viewing condition: 0.7 m from a 0.7 m wide screen 3840 pixels across, 67.0206 pixels per
// degree (NVIDIA's tool prints it rounded, "67").
inline constexpr double kFlipDefaultPixelsPerDegree = pixels_per_degree_at_centre(0.7, 0.7, 3840);
// The pixels per degree FLIP accepts. Its filters are sized in degrees (radius ~ 0.14 ppd pixels for the CSF,
// ~ 0.12 ppd for the features): 1e30 asked for a filter of 1e29 taps and crashed (issue 26 item 8); below 1 a
// pixel spans more than a degree and the kernels shrink to their centre tap. 1000 is far past any display.
inline constexpr double kFlipMinPixelsPerDegree = 1.0;
inline constexpr double kFlipMaxPixelsPerDegree = 1000.0;

}  // namespace temporal
