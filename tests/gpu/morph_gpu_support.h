// Shared by morph-120hz's GPU tests (morph_gpu_test.cpp, didyk_gpu_test.cpp): the output slots a MorphMethod::run
// fills, and the agreement of the GPU method's slots with the C++ method's.
#pragma once

#include "gpu_support.h"
#include "temporal/morph/morph.h"

#include <string>
#include <vector>

namespace temporal::test {

// `count` output slots of width x height with R, G, B (and with `debug_layers` kMorphDebugLayers), every value 9: no
// method writes 9, so a plane a method leaves unwritten (MorphMethod::run must write every one) shows.
inline std::vector<Image> stale_slots(std::size_t count, int width, int height, bool debug_layers) {
  std::vector<Image> out(count, Image(width, height));
  for (auto& o : out) {
    for (const char* c : {"R", "G", "B"}) o.add_channel(c, 9.0f);
    if (debug_layers)
      for (const char* ch : morph::kMorphDebugLayers) o.add_channel(ch, 9.0f);
  }
  return out;
}

// The worst agreement of `planes` over every slot, values differing by more than `beyond` counted.
inline Agreement slots_agreement(const std::vector<Image>& gpu, const std::vector<Image>& cpu,
                                 const std::vector<std::string>& planes, double beyond = 0.0) {
  Agreement worst;
  EXPECT_EQ(gpu.size(), cpu.size());
  for (std::size_t k = 0; k < gpu.size() && k < cpu.size(); ++k) worst.merge(agreement(gpu[k], cpu[k], planes, beyond));
  return worst;
}

}  // namespace temporal::test
