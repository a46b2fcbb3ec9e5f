// Synthetic RGB frames and filter inputs for the phlm_test suites (phlm_test.cpp, baselines_test.cpp): one copy
// of the set-up both need.
#pragma once

#include "temporal/core/image.h"
#include "temporal/phlm/frame_filter.h"

#include <cstddef>
#include <functional>
#include <string>
#include <vector>

namespace temporal::phlm::test_frames {

inline const std::vector<std::string> kRgb = {"R", "G", "B"};

// A w x h frame with channels R, G, B; f(x, y, c) gives each value (c: 0 = R, 1 = G, 2 = B).
inline Image make_frame(int w, int h, const std::function<float(int, int, int)>& f) {
  Image img(w, h);
  for (int c = 0; c < 3; ++c) {
    float* p = img.add_channel(kRgb[std::size_t(c)]);
    for (int y = 0; y < h; ++y)
      for (int x = 0; x < w; ++x) p[std::size_t(y * w + x)] = f(x, y, c);
  }
  return img;
}

// A filter input that filters img's R, G, B (reset: the first frame of a shot).
inline FilterInput input_for(const Image& img, bool reset = false) {
  FilterInput in;
  in.color = &img;
  in.channels = kRgb;
  in.reset = reset;
  return in;
}

}  // namespace temporal::phlm::test_frames
