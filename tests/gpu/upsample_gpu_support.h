// Shared by the upsampling methods' GPU tests (upsample_gpu_test.cpp, herzog_gpu_test.cpp, taau_gpu_test.cpp,
// drobot_gpu_test.cpp, upsample_render_gpu_test.cpp): the synthetic sequence, a method's options and C++ state,
// and the comparisons each of them makes between a method's C++ state (the reference of record) and its GPU state:
// over a sequence (compare_states, compare_method) and the bounds that comparison is held to
// (expect_state_agreement), in every mode and for every option variant (expect_agreement_in_every_mode,
// expect_every_variant_agrees), after a state file moved between the devices (resume_on_the_other_device,
// expect_resumes_on_either_device), through the registry's implementations (compare_registered), and what load()
// says of a state file that lacks a plane or holds a NaN (load_error_with_only).
#pragma once

#include "gpu_methods.h"  // libtemporal/src/upsample (internal)
#include "gpu_support.h"
#include "synthetic.h"  // tests/upsample
#include "upsample_context.h"
#include "temporal/gpu/timer.h"

#include <gtest/gtest.h>

#include <functional>
#include <limits>
#include <string>
#include <vector>

namespace temporal::test {

// The synthetic G-buffer sequence of the upsampling GPU tests: 76 x 52 (19 x 13 low-resolution pixels, 38 x 26
// gradient cells, none a multiple of the 16 x 16 work group), k = 4 regular jitter, a panning textured background,
// a foreground square moving over it with its own depth and id (disocclusions every frame), and a NaN
// low-resolution sample every frame: it must carry weight 0 and never enter the history.
inline std::vector<SyntheticFrame> upsample_gpu_sequence(int n) {
  SyntheticScene scene;
  scene.width = 76;
  scene.height = 52;
  scene.k = 4;
  scene.camera_velocity = {0.6f, -0.4f};
  scene.object = true;
  scene.object_velocity = {1.5f, 0.7f};
  std::vector<SyntheticFrame> frames;
  for (int t = 0; t < n; ++t) {
    frames.push_back(make_frame(scene, t));
    frames.back().low.plane("G")[std::size_t((5 * t) % 200)] = std::numeric_limits<float>::quiet_NaN();
  }
  return frames;
}

// Default options with `method`'s own options (OwnOptions, e.g. HerzogOptions) changed by `set` (may be empty).
template <class OwnOptions>
upsample::Options options_with(const char* method, const std::function<void(OwnOptions&)>& set) {
  upsample::Options o;  // per_method holds every method's options with their defaults
  MethodOptions* m = o.per_method.find(method);
  EXPECT_NE(m, nullptr) << method;
  if (m && set) set(static_cast<OptionsOf<OwnOptions>&>(*m));
  return o;
}

// One variant of a method's options in a comparison: its name and what it changes (empty: the defaults).
template <class OwnOptions>
struct OptionVariant {
  const char* name;
  std::function<void(OwnOptions&)> set;
};

// The registry's C++ ("cpu") state of `method`, the reference of record.
inline std::unique_ptr<upsample::MethodState> cpu_state(const char* method, const upsample::Options& o,
                                                        const upsample::Geometry& g) {
  return find_implementation(*upsample::find_entry(method), kCpuDevice)->make(o, g);
}

// The frames both states run and how: `cut` is the frame that starts without history like frame 0 (-1: none);
// FrameContext::prev_z (the warped depth) is the G-buffer plane `warped_depth_plane` when named (the renderer's
// prevDepth.Z), else with `warped` the depth itself (the synthetic surfaces are fronto-parallel); `debug` asks the
// states for their debug planes.
struct StateSequence {
  const std::vector<SyntheticFrame>& frames;
  int cut = -1;
  bool warped = false, debug = false;
  const char* warped_depth_plane = nullptr;
};

// A debug plane's bound: the worst |GPU - CPU| over the sequence, divided by max(relative_floor, |CPU|) when
// `relative`. `may_be_absent`: the plane is missing from both outputs in some of the method's modes (it must then be
// missing from both).
struct DebugPlaneBound {
  const char* name;
  bool relative;
  double bound;
  bool may_be_absent = false;
  double relative_floor = 1e-6;
};

struct StateComparison {
  Agreement colour;                          // R, G, B over every frame
  std::size_t stat_mismatches = 0;           // frames whose FrameStats (hole and history pixels) differ
  std::size_t exact_plane_mismatches = 0;    // values of the exactly compared debug planes that differ
  std::size_t history_pixels = 0, misses = 0;  // the C++ state's counts over the frames with history
  std::vector<double> debug;                 // the worst difference per DebugPlaneBound, in their order
  Image last_cpu;                            // the C++ output of the last frame
};

// Runs the C++ state `cpu` and the GPU state `gpu` on the same frames and compares their outputs frame by frame: the
// colour, the statistics, and with s.debug the planes of `exact_planes` (decisions, equal value for value) and of
// `debug_bounds`. `each_frame(cpu_output, gpu_output)`, when given, sees both outputs of every frame.
inline StateComparison compare_states(upsample::MethodState& cpu, upsample::MethodState& gpu,
                                      const upsample::Options& o, const StateSequence& s,
                                      const std::vector<std::string>& exact_planes = {},
                                      const std::vector<DebugPlaneBound>& debug_bounds = {},
                                      const std::function<void(const Image&, const Image&)>& each_frame = {}) {
  static const std::vector<std::string> kRgb = {"R", "G", "B"};
  StateComparison r;
  r.debug.assign(debug_bounds.size(), 0.0);
  upsample::FrameContext f;
  for (int t = 0; t < int(s.frames.size()); ++t) {
    const SyntheticFrame& frame = s.frames[std::size_t(t)];
    build_context(f, o, frame, s.warped, s.debug);
    if (s.warped_depth_plane) {
      f.prev_z = frame.gbuffer.plane(s.warped_depth_plane);
      EXPECT_NE(f.prev_z, nullptr) << s.warped_depth_plane;
    }
    const bool history = t > 0 && t != s.cut;
    upsample::FrameStats sc, sg;
    const Image& a = cpu.run(f, history, sc);
    const Image& b = gpu.run(f, history, sg);
    EXPECT_TRUE(gpu.run_status()) << gpu.run_status().error().message;
    r.colour.merge(agreement(b, a, kRgb));
    r.stat_mismatches += (sc.hole_pixels != sg.hole_pixels) + (sc.history_pixels != sg.history_pixels);
    if (history) {
      r.history_pixels += sc.history_pixels;
      r.misses += sc.hole_pixels;
    }
    if (t + 1 == int(s.frames.size())) r.last_cpu = a;
    if (each_frame) each_frame(a, b);
    if (!s.debug) continue;
    for (const auto& name : exact_planes) r.exact_plane_mismatches += differing_values(a, b, name);
    for (std::size_t d = 0; d < debug_bounds.size(); ++d) {
      const DebugPlaneBound& bound = debug_bounds[d];
      const float* pa = a.plane(bound.name);
      const float* pb = b.plane(bound.name);
      if (bound.may_be_absent)
        EXPECT_EQ(pa != nullptr, pb != nullptr) << bound.name;
      else
        EXPECT_TRUE(pa && pb) << bound.name;
      if (!pa || !pb) continue;
      for (std::size_t i = 0; i < a.pixel_count(); ++i) {
        const double diff = std::abs(double(pa[i]) - pb[i]);
        const double scaled = bound.relative ? diff / std::max(bound.relative_floor, std::abs(double(pa[i]))) : diff;
        r.debug[d] = std::max(r.debug[d], scaled);
      }
    }
  }
  return r;
}

// `method`'s C++ state and the GPU state `make_gpu` makes, compared on s (compare_states).
using GpuStateFactory = Expected<std::unique_ptr<upsample::MethodState>> (*)(std::shared_ptr<gpu::Context>,
                                                                               const upsample::Options&,
                                                                               const upsample::Geometry&);
inline StateComparison compare_method(const std::shared_ptr<gpu::Context>& ctx, const char* method,
                                      GpuStateFactory make_gpu, const upsample::Options& o, const StateSequence& s,
                                      const std::vector<std::string>& exact_planes = {},
                                      const std::vector<DebugPlaneBound>& debug_bounds = {},
                                      const std::function<void(const Image&, const Image&)>& each_frame = {}) {
  const upsample::Geometry g = geometry_of(s.frames[0]);
  auto cpu = cpu_state(method, o, g);
  auto gpu = make_gpu(ctx, o, g);
  EXPECT_TRUE(gpu) << gpu.error().message;
  if (!gpu) return {};
  return compare_states(*cpu, **gpu, o, s, exact_planes, debug_bounds, each_frame);
}

// The bounds of a method's comparison on the synthetic sequence: the colour within max_abs and min_psnr, every
// statistic and exactly compared plane equal, each debug plane within its bound, and a sequence that did reproject
// history and disocclude (else the comparison tested less than it claims).
inline void expect_state_agreement(const StateComparison& r, double max_abs, double min_psnr,
                                   const std::vector<DebugPlaneBound>& debug_bounds) {
  expect_within(r.colour, max_abs, min_psnr);
  EXPECT_EQ(r.stat_mismatches, 0u);
  EXPECT_EQ(r.exact_plane_mismatches, 0u);
  for (std::size_t d = 0; d < debug_bounds.size() && d < r.debug.size(); ++d)
    EXPECT_LE(r.debug[d], debug_bounds[d].bound) << debug_bounds[d].name;
  EXPECT_GT(r.history_pixels, 0u);  // the sequence reprojects history ...
  EXPECT_GT(r.misses, 0u);          // ... and has disocclusions
}

// A method's MatchesTheCppMethod: its defaults without and with the warped depth, without and with the debug planes,
// `compare(warped, debug)` (the method's compare_method) held to `expect` (its expect_state_agreement); the measured
// max |GPU - CPU| and PSNR recorded as the test property max_abs_<w><d> (w: warped, d: debug).
template <class Compare, class Expect>
void expect_agreement_in_every_mode(Compare compare, Expect expect) {
  for (bool warped : {false, true})
    for (bool debug : {false, true}) {
      SCOPED_TRACE(::testing::Message() << "warped " << warped << " debug " << debug);
      const auto r = compare(warped, debug);
      expect(r);
      ::testing::Test::RecordProperty(std::string("max_abs_") + (warped ? "w" : "") + (debug ? "d" : ""),
                                      (::testing::Message() << r.colour.max_abs << " psnr " << r.colour.psnr)
                                          .GetString());
    }
}

// A method's MatchesTheCppMethodForEveryOption: each variant's options (options_with(method, v.set)) compared with
// warped depth and debug planes, `compare(options)`, and held to `expect(variant, comparison)`; and each variant's
// option reaches the C++ method: its last output differs from the defaults' (the first variant, set empty) by more
// than 1e-4 in one of `changed` (else the comparison tests nothing new). The measured figures, max |GPU - CPU|, PSNR
// and what `figures(comparison)` adds (the debug planes' worst differences), recorded as the test property
// max_abs_<variant>.
template <class OwnOptions, class Compare, class Expect, class Figures>
void expect_every_variant_agrees(const char* method, const std::vector<OptionVariant<OwnOptions>>& variants,
                                 Compare compare, Expect expect, const std::vector<std::string>& changed,
                                 Figures figures) {
  Image defaults;
  for (const OptionVariant<OwnOptions>& v : variants) {
    SCOPED_TRACE(v.name);
    const auto r = compare(options_with<OwnOptions>(method, v.set));
    expect(v, r);
    if (!v.set)
      defaults = r.last_cpu;
    else
      EXPECT_GT(agreement(r.last_cpu, defaults, changed).max_abs, 1e-4);
    ::testing::Test::RecordProperty(
        std::string("max_abs_") + v.name,
        (::testing::Message() << r.colour.max_abs << " psnr " << r.colour.psnr << figures(r)).GetString());
  }
}

// A state's planes in a state file (the same whichever device wrote them): float planes and the id plane.
struct StatePlanes {
  std::vector<std::string> floats;
  std::string ids;
};

// The state round trip: the first `split` frames (warped depth, no debug) on one device, its state file's planes
// loaded into a new state on the other device, the remaining frames there; returns the agreement of the last frame
// with the uninterrupted C++ run over every frame. `planes` must be in the state file.
inline Agreement resume_on_the_other_device(const std::shared_ptr<gpu::Context>& ctx, const char* method,
                                            GpuStateFactory make_gpu, const upsample::Options& o,
                                            const std::vector<SyntheticFrame>& frames, int split, bool gpu_first,
                                            const StatePlanes& planes) {
  static const std::vector<std::string> kRgb = {"R", "G", "B"};
  const upsample::Geometry g = geometry_of(frames[0]);
  upsample::FrameContext f;
  upsample::FrameStats stats;
  auto reference = cpu_state(method, o, g);
  Image expected;
  for (int t = 0; t < int(frames.size()); ++t) {
    build_context(f, o, frames[std::size_t(t)], true, false);
    expected = reference->run(f, t > 0, stats);
  }
  auto cpu = cpu_state(method, o, g);
  auto gpu = make_gpu(ctx, o, g);
  EXPECT_TRUE(gpu) << gpu.error().message;
  if (!gpu) return Agreement::failed();
  upsample::MethodState& first = gpu_first ? **gpu : *cpu;
  upsample::MethodState& second = gpu_first ? *cpu : **gpu;
  for (int t = 0; t < split; ++t) {
    build_context(f, o, frames[std::size_t(t)], true, false);
    first.run(f, t > 0, stats);
  }
  Image state(g.W, g.H);
  first.save(state);
  for (const auto& n : planes.floats) EXPECT_TRUE(state.plane(n)) << n;
  EXPECT_TRUE(state.uint_plane(planes.ids)) << planes.ids;
  const Status loaded = second.load(state);
  EXPECT_TRUE(loaded) << loaded.error().message;
  if (!loaded) return Agreement::failed();
  Image got;
  for (int t = split; t < int(frames.size()); ++t) {
    build_context(f, o, frames[std::size_t(t)], true, false);
    got = second.run(f, true, stats);
    EXPECT_TRUE(second.run_status()) << second.run_status().error().message;
  }
  return agreement(got, expected, kRgb);
}

// What a new GPU state's load() says of a state file (the synthetic sequence's size) that holds only the float
// planes `planes` (zeros): the error's message, empty when it loaded. `damaged` (one of `planes`, or empty) gets a
// NaN at (1, 1), inside every plane's corner (the low-resolution planes fill the top-left lw x lh of the channel): a
// plane that every --state-out writes finite must be refused by name (get_plane's StateValues::Finite), as the C++
// states refuse it (tests/upsample/state_test.cpp).
inline std::string load_error_with_only(const std::shared_ptr<gpu::Context>& ctx, GpuStateFactory make_gpu,
                                        const upsample::Options& o, const std::vector<std::string>& planes,
                                        const std::string& damaged = {}) {
  const upsample::Geometry g = geometry_of(upsample_gpu_sequence(1)[0]);
  auto gpu = make_gpu(ctx, o, g);
  EXPECT_TRUE(gpu) << gpu.error().message;
  if (!gpu) return gpu.error().message;
  Image state(g.W, g.H);
  for (const auto& n : planes) state.add_channel(n);
  if (!damaged.empty()) {
    float* p = state.plane(damaged);
    EXPECT_TRUE(p) << damaged;
    if (p) p[std::size_t(g.W) + 1] = std::numeric_limits<float>::quiet_NaN();
  }
  const Status st = (*gpu)->load(state);
  return st ? std::string() : st.error().message;
}

// One case of a method's state round trips: the options, the planes its state file must hold, and the suffix of the
// measured figure's test property (round_trip_max_abs_<gpu_cpu|cpu_gpu><suffix>).
struct ResumeCase {
  const char* suffix;
  upsample::Options options;
  StatePlanes planes;
};

// Each case's round trip on `frames` in both directions (half the frames on one device, the rest on the other:
// resume_on_the_other_device) within the method's bounds, the measured max |GPU - CPU| recorded as a test property.
inline void expect_resumes_on_either_device(const std::shared_ptr<gpu::Context>& ctx, const char* method,
                                            GpuStateFactory make_gpu, const std::vector<SyntheticFrame>& frames,
                                            const std::vector<ResumeCase>& cases, double max_abs, double min_psnr) {
  const int split = int(frames.size()) / 2;
  for (const ResumeCase& c : cases)
    for (bool gpu_first : {true, false}) {
      SCOPED_TRACE(::testing::Message() << (gpu_first ? "GPU -> CPU" : "CPU -> GPU") << " " << c.suffix);
      const Agreement a =
          resume_on_the_other_device(ctx, method, make_gpu, c.options, frames, split, gpu_first, c.planes);
      expect_within(a, max_abs, min_psnr);
      ::testing::Test::RecordProperty(std::string("round_trip_max_abs_") + (gpu_first ? "gpu_cpu" : "cpu_gpu") +
                                          c.suffix,
                                      (::testing::Message() << a.max_abs).GetString());
    }
}

// The registry's "gpu" implementation of a method (what --device gpu picks) against its "cpu" one on `frames`
// (warped depth, no cut): the colour's agreement, and whether the GPU state reports its kernel time.
struct RegisteredComparison {
  Agreement colour = Agreement::failed();  // until both implementations ran
  bool timed = false;
};
inline RegisteredComparison compare_registered(const upsample::MethodEntry& entry, const upsample::Options& o,
                                               const std::vector<SyntheticFrame>& frames) {
  RegisteredComparison r;
  const auto* gpu_implementation = find_implementation(entry, kGpuDevice);
  const auto* cpu_implementation = find_implementation(entry, kCpuDevice);
  EXPECT_TRUE(gpu_implementation && cpu_implementation) << entry.info.name;
  if (!gpu_implementation || !cpu_implementation) return r;
  const upsample::Geometry g = geometry_of(frames[0]);
  auto gpu = gpu_implementation->make(o, g);
  auto cpu = cpu_implementation->make(o, g);
  EXPECT_TRUE(gpu && cpu) << entry.info.name;
  if (!gpu || !cpu) return r;
  r.timed = dynamic_cast<gpu::TimedKernel*>(gpu.get()) != nullptr;
  r.colour = compare_states(*cpu, *gpu, o, {frames, -1, true, false}).colour;
  return r;
}

}  // namespace temporal::test
