// Shared by didyk's GPU tests: didyk_gpu_test.cpp (synthetic motion; gpu_morph_test, which links no renderer and no
// image library, so it can run on a machine that has only a GPU driver) and didyk_render_gpu_test.cpp (a sequence
// rendered by the renderer; gpu_render_test). The synthetic frames, and the comparison of the GPU kernels
// (didyk_gpu.cpp) with the C++ reference of record (didyk.cpp) on a list of frames.
//
// Why the outputs are not bit for bit equal (measured values and bounds in docs/gpu.md, "Tolerances"):
//  - float rounding: GCC (-march=native) contracts multiply-adds into FMAs where it chooses (the B-spline row and
//    column sums of the blur, the [1 2 1]/4 pyramid, the barycentric interpolation of texture coordinates and
//    attributes, the compensation's (1 + B) o - B L^g), and the driver chooses its own; the fast log2/exp2 of
//    core/fast_math.h are the same polynomials with the same constants (bit patterns), but their division
//    (m - 1) / (m + 1) and the same contractions differ in the last bit. This moves values by a few 1e-7.
//  - decisions taken on those values: where a texture coordinate rounded differently lands exactly on a pixel
//    border, the nearest source pixel of the depth test or a bilinear tap changes, and that pixel shows a neighbour's
//    value. What the rasteriser decides in double (coverage, the top-left rule, the barycentric weights) is computed
//    from floats whose products fit a double's mantissa at these coordinate sizes, so an FMA or not gives the same
//    bits on both sides and no pixel changes triangle (measured: debug.grid and the coverage are equal).
#pragma once

#include "morph_gpu_support.h"
#include "temporal/core/method.h"
#include "temporal/gpu/timer.h"
#include "temporal/morph/gpu_methods.h"
#include "temporal/morph/methods.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <memory>
#include <string>
#include <vector>

namespace temporal::test::didyk {

using morph::MorphMethod;
using morph::MorphOptions;
using morph::MorphTimings;

inline const std::vector<std::string> kRgb = {"R", "G", "B"};

struct Frame {
  Image color, gbuffer;
};

// Smooth texture in [0.1, 0.6] plus a bright stripe pattern (values up to 0.95, so the compensation's range rules
// act) over 83 x 61 pixels (not multiples of the 16 x 16 work group or of the 8-pixel grid cell). The square (depth
// 4) moves by (5.3, -2.7) px per frame; the background (depth 20) pans by (-1.6, 0.9) with a swirl of up to 1.5 px.
inline Frame synthetic_frame(int t) {
  const int w = 83, h = 61;
  Frame f;
  f.color = Image(w, h);
  f.gbuffer = Image(w, h);
  float* mx = f.gbuffer.add_channel("motion.X");
  float* my = f.gbuffer.add_channel("motion.Y");
  float* d = f.gbuffer.add_channel("depth.Z");
  for (int c = 0; c < 3; ++c) {
    float* p = f.color.add_channel(kRgb[std::size_t(c)]);
    for (int y = 0; y < h; ++y)
      for (int x = 0; x < w; ++x) {
        const float u = float(x) + 0.5f + 7.0f * float(t), v = float(y) + 0.5f;
        const float base = 0.35f + 0.15f * std::sin(0.45f * u + 0.7f * float(c)) * std::cos(0.6f * v);
        p[y * w + x] = ((x + 2 * y) % 11 == 0) ? 0.95f : base;
      }
  }
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x) {
      const int i = y * w + x;
      const bool sq = x >= 20 && x < 50 && y >= 15 && y < 40;
      mx[i] = sq ? 5.3f : -1.6f + 1.5f * std::sin(0.11f * float(y) + 0.3f * float(t));
      my[i] = sq ? -2.7f : 0.9f + 1.2f * std::cos(0.09f * float(x));
      d[i] = sq ? 4.0f : 20.0f + 0.01f * float(x % 3);
    }
  return f;
}

struct Outcome {
  test::Agreement colour;            // R, G, B of every slot (values beyond 1e-5 counted)
  test::Agreement debug_values;      // debug.distortion, debug.blur, debug.H, debug.Hprime
  std::size_t grid_pixels = 0;       // pixels of debug.grid set in the C++ output
  std::size_t grid_differing = 0;    // ... and pixels of debug.grid that differ
};

// Runs the C++ method (the registry's kCpuDevice implementation) and the GPU one on `frames` and compares every
// slot.
inline Outcome compare(std::shared_ptr<gpu::Context> ctx, const std::vector<Frame>& frames, const std::vector<std::string>& args,
                bool debug, float pixels_per_degree = 0.0f) {
  auto options = morph::make_options("didyk", args);
  EXPECT_TRUE(options) << options.error().message;
  Outcome r;
  if (!options) return r;
  options->factor = 3;
  options->debug_layers = debug;
  options->pixels_per_degree = pixels_per_degree;
  const morph::MethodEntry* entry = morph::find_entry("didyk");
  const auto* cpu_impl = find_implementation(*entry, kCpuDevice);
  EXPECT_TRUE(cpu_impl);
  if (!cpu_impl) return r;
  auto cpu = cpu_impl->make(*options);
  auto gpu = make_didyk_method_gpu(ctx, *options);
  EXPECT_TRUE(gpu) << gpu.error().message;
  if (!gpu) return r;
  for (const Frame& f : frames) {
    std::vector<Image> a = test::stale_slots(std::size_t(options->factor), f.color.width(), f.color.height(), debug);
    std::vector<Image> b = a;
    MorphTimings ta, tb;
    cpu->run(f.color, &f.gbuffer, nullptr, a, ta);
    (*gpu)->run(f.color, &f.gbuffer, nullptr, b, tb);
    EXPECT_TRUE((*gpu)->run_status()) << (*gpu)->run_status().error().message;
    r.colour.merge(test::slots_agreement(b, a, kRgb, 1e-5));
    if (debug) {
      r.debug_values.merge(test::slots_agreement(b, a, {"debug.distortion", "debug.blur", "debug.H", "debug.Hprime"}));
      for (std::size_t k = 0; k < a.size(); ++k) {
        const float* grid = a[k].plane("debug.grid");
        r.grid_pixels +=
            std::size_t(std::count_if(grid, grid + f.color.pixel_count(), [](float v) { return v != 0.0f; }));
        r.grid_differing += test::differing_values(b[k], a[k], "debug.grid");
      }
    }
    const auto* timed = dynamic_cast<const gpu::TimedKernel*>(gpu->get());
    EXPECT_TRUE(timed && timed->last_timing().kernel_ms > 0.0 && timed->last_timing().bytes_moved > 0.0);
    EXPECT_GT(tb.total_ms(), 0.0);
  }
  return r;
}

inline void report(const char* what, const Outcome& r) {
  std::printf("%s: colour max |GPU - CPU| %.3g, PSNR %.1f dB, %zu of %zu values beyond 1e-5; debug values max %.3g; "
              "debug.grid %zu of %zu pixels differ\n",
              what, r.colour.max_abs, r.colour.psnr, r.colour.values_beyond, r.colour.values, r.debug_values.max_abs,
              r.grid_differing, r.grid_pixels);
}

inline std::vector<Frame> synthetic_frames() { return {synthetic_frame(0), synthetic_frame(1), synthetic_frame(2)}; }

}  // namespace temporal::test::didyk
