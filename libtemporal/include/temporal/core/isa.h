// Run-time choice of the instruction set for the hot pixel kernels (FLIP's filters and colour passes, ...).
//
// The default build compiles for x86-64-v2 (SSE4.2; every x86-64 CPU since about 2009), so one binary runs on
// any of them. The kernels that dominate the tools' CPU time are compiled three times in their source file,
// under the TEMPORAL_ISA_V3_BEGIN / TEMPORAL_ISA_V4_BEGIN pragmas below: for the baseline (x86-64-v2),
// x86-64-v3 (AVX2, FMA) and x86-64-v4 (AVX-512 F/BW/CD/DQ/VL), and each call picks its copy by isa::active().
// A build whose baseline already has AVX (TEMPORAL_NATIVE=ON, i.e. -march=native, for local experiments) and a
// build for another CPU or compiler compile one copy only: there active() is Level::Native and nothing can be
// forced.
//
// Results: the copies run the same operations in the same order per pixel; v3 and v4 may contract a multiply
// and an add into one fused multiply-add (FMA, one rounding instead of two), v2 has no FMA. So v2 and v3 can
// differ in the last bits of a float, v3 and v4 agree (tests/core/isa_test.cpp checks both on the build
// machine). One exception: phlm's kernel compiles its v4 copy for 256-bit vectors (phlm_kernels.inc), and there
// v3 and v4 contract differently, within the bound isa_test states.
#pragma once

#include <string_view>

// Several kernel copies: x86-64 with GCC (the pragmas are GCC's), and a baseline without AVX (with -march=native
// on a machine with AVX2 the "baseline" copy would be AVX2 code already).
#if defined(__x86_64__) && defined(__GNUC__) && !defined(__clang__) && !defined(__AVX__)
#define TEMPORAL_ISA_DISPATCH 1
// The target options are ISA extensions added to the baseline, not `arch=x86-64-v3`: GCC inlines a function
// into one with another target only when their `arch` is the same, and the kernels rely on inlining the
// header helpers (fast_math, std::min) compiled for the baseline. v3: AVX2, FMA, BMI1/2, LZCNT, MOVBE, F16C
// (the psABI's x86-64-v3 list); v4 adds AVX-512 F, BW, CD, DQ, VL and lets the vectoriser use 512-bit vectors
// (GCC prefers 256-bit ones by default, which would leave AVX-512 no faster than AVX2 in plain loops).
#define TEMPORAL_ISA_V3_BEGIN \
  _Pragma("GCC push_options") _Pragma("GCC target(\"avx2,fma,bmi,bmi2,lzcnt,movbe,f16c,popcnt\")")
#define TEMPORAL_ISA_V4_BEGIN                                                                                  \
  _Pragma("GCC push_options") _Pragma("GCC target(\"avx2,fma,bmi,bmi2,lzcnt,movbe,f16c,popcnt,avx512f,avx512bw,\
avx512cd,avx512dq,avx512vl,prefer-vector-width=512\")")
#define TEMPORAL_ISA_END _Pragma("GCC pop_options")
#else
#define TEMPORAL_ISA_DISPATCH 0
#endif

// Runs `...` (a statement, usually a return) with the namespace alias NS naming the kernel copy of the active
// level (temporal/core/isa_copies.inc): TEMPORAL_ISA_CALL(copy, return std::make_unique<copy::HerzogState>(o, g)).
// Exactly one copy runs: a statement that does not return (fxaa's `edges = copy::run_fxaa(...)`) leaves the switch.
#if TEMPORAL_ISA_DISPATCH
#define TEMPORAL_ISA_CALL(NS, ...)                \
  switch (::temporal::isa::active()) {            \
    case ::temporal::isa::Level::V4: {            \
      namespace NS = v4;                          \
      __VA_ARGS__;                                \
      break;                                      \
    }                                             \
    case ::temporal::isa::Level::V3: {            \
      namespace NS = v3;                          \
      __VA_ARGS__;                                \
      break;                                      \
    }                                             \
    default: {                                    \
      namespace NS = v2;                          \
      __VA_ARGS__;                                \
      break;                                      \
    }                                             \
  }
#else
#define TEMPORAL_ISA_CALL(NS, ...) \
  {                                \
    namespace NS = native;         \
    __VA_ARGS__;                   \
  }
#endif

namespace temporal::isa {

enum class Level {
  V2,      // x86-64-v2: SSE4.2, 128-bit vectors, no FMA
  V3,      // x86-64-v3: AVX2 + FMA, 256-bit
  V4,      // x86-64-v4: AVX-512, 512-bit
  Native,  // a build with one kernel copy (TEMPORAL_NATIVE=ON, or not x86-64 with GCC)
};

// True when the kernels exist in several copies (the default x86-64 build with GCC).
bool dispatching();

// Whether this CPU (and its operating system, which must save the wider registers) can run `level`.
bool supported(Level level);

// The level the kernels run at now: the highest the CPU supports, or the one TEMPORAL_ISA names (v2, v3 or v4;
// a level above the CPU's is lowered to the CPU's, an unknown value is ignored) - read once, at the first call.
Level active();

// The level TEMPORAL_ISA asked for and why it was not used, or empty: for a tool's --verbose/--version line.
std::string_view environment_note();

// "v2", "v3", "v4" or "native".
std::string_view name(Level level);

// Runs the kernels at `level` while it lives (tests and benchmarks compare the copies); the previous level
// returns at destruction. A level the CPU cannot run, or any level in a build without dispatch, leaves the
// active level unchanged: check supported() first. Not for use while kernels run on other threads.
class ScopedLevel {
 public:
  explicit ScopedLevel(Level level);
  ~ScopedLevel();
  ScopedLevel(const ScopedLevel&) = delete;
  ScopedLevel& operator=(const ScopedLevel&) = delete;

 private:
  Level previous_;
};

}  // namespace temporal::isa
