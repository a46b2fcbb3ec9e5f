// taau's options and the FSR 2 constants, shared by its C++ implementation (taau.cpp) and its GLSL one
// (taau_gpu.cpp), which must read the same fields and constants. Internal (not installed), like method.h.
#pragma once

#include "method.h"

#include "temporal/core/method.h"
#include "temporal/core/params.h"

#include <algorithm>
#include <cmath>
#include <string>

namespace temporal::upsample {

// FSR 2 constants (ffx_fsr2_common.h, 2.2).
constexpr float kLanczosWeightScale = 1.0f / 12.0f;  // fUpsampleLanczosWeightScale
constexpr float kMaxAccumulation = 1.0f;             // fMaxAccumulationLanczosWeight
constexpr float kAverageLanczosWeight = 0.74f * kLanczosWeightScale;    // fAverageLanczosWeightPerFrame
constexpr float kEpsilon = 1e-3f;                                       // FSR2_EPSILON
constexpr float kRectifiedAccumulation = 0.1f;  // RectifyHistory: accumulation of a clamped history, at most
constexpr float kSimilarLuma = 1.05f;           // ComputeThinFeatureConfidence: similar_threshold

// taau's parameters; the FSR 2 constants above are not options.
struct TaauOptions {
  bool locks = true;  // step 5
  float box_scale = 0.0f;  // s of step 3; 0 = FSR 2.2's lerp(min(20, k^6), 1, saturate(velocity / 20))
  float lock_luma_change = 0.1f;  // a lock dies when 1 - min/max of its luminance and this frame's exceeds this
  float motion_accumulation = 3.0f * kLanczosWeightScale;  // FSR 2.0 accumulationMaxOnMotion
  std::string history = "catmull-rom";                     // the history's colour filter (step 1)

  ParamList params() {
    return {
        Param::flag_off("--no-locks", "no thin-feature locks (FSR 2 ffx_fsr2_lock.h)", &locks),
        Param::real("--box-scale",
                    "rectification box mean +- s sigma (in the samples' min/max); 0 = FSR 2.2's, 20 when still and 1 "
                    "from 20 px/frame",
                    &box_scale, 0.0, 100.0),
        Param::real("--lock-luma-change", "a lock dies when its luminance changes by more than this (relative)",
                    &lock_luma_change, 0.0, 1.0),
        Param::real("--motion-accumulation",
                    "cap of the accumulation weight of a moving pixel (FSR 2.0 accumulationMaxOnMotion: 3/12; the "
                    "still cap is 1)",
                    &motion_accumulation, 0.0, 1.0),
        Param::choice("--history",
                      "filter of the history's colour: catmull-rom (UE4 TAAU, Karis 2014) where the reprojection "
                      "module kept all four bilinear taps, else its bilinear fetch; bilinear everywhere",
                      &history, {"catmull-rom", "bilinear"}),
    };
  }
};

// The run's taau options (the defaults when the run has none).
const TaauOptions& taau_options(const Options& o);

// What one frame's pixels share, from the factor k.
struct TaauConstants {
  float scale_influence;      // step 3's box scale: FSR 2.2 RectifyHistory, fScaleFactorInfluence = min(20, k^6)
  float bias_history;         // kernel bias with history (FSR 2 ComputeMaxKernelWeight, fKernelSizeBias = 1)
  float lifetime_per_weight;  // lock lifetime spent per unit of accumulated weight (FSR 2 FinalizeLockStatus)
};

inline TaauConstants taau_constants(int k) {
  TaauConstants t;
  t.scale_influence = std::min(20.0f, std::pow(float(k) * float(k), 3.0f));  // (1 / (1/k * 1/k))^3
  t.bias_history = std::min(1.99f, 1.0f + (float(k) - 1.0f));
  t.lifetime_per_weight = 1.0f / (float(k * k) * kAverageLanczosWeight);  // a jitter cycle of average weight takes 1
  return t;
}

}  // namespace temporal::upsample
