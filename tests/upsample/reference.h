// Plain implementations of every upsampling method, written from the header formulas (joint_bilateral.h,
// history.h, drobot.h, temporal/core/reproject.h) and docs/upsample-st.md, one pixel at a time in double loops,
// without any of the production code's tables, row caches, runs or schedules. Slow and obviously correct: the
// reference that tests/upsample/reference_test.cpp compares the fast kernels with, on any CPU.
#pragma once

#include "temporal/core/image.h"
#include "temporal/upsample/upsample.h"

#include <cstdint>
#include <string>
#include <vector>

namespace temporal::test {

class PlainUpsampler {
 public:
  explicit PlainUpsampler(const upsample::Options& options);
  // Same contract as upsample::Upsampler::process (R, G, B or any channels; `cut` discards the history). Returns
  // the payload channels at full resolution (no debug layers, no antialiasing downsample, no demodulation).
  Image process(const Image& gbuffer, const Image& low, const std::vector<std::string>& channels, bool cut);

 private:
  struct Frame;
  void spatial(const Frame& f, Image& out) const;
  void temporal(const Frame& f, Image& out);
  void herzog(const Frame& f, Image& out);
  void taau(const Frame& f, Image& out);
  void drobot_cache(const Frame& f, Image& out);
  void drobot_refresh(const Frame& f, Image& out);

  upsample::Options options_;
  std::string method_;
  bool have_history_ = false;
  // History of the previous frame.
  Image prev_out_;
  std::vector<float> prev_z_;
  std::vector<std::uint32_t> prev_id_;
  std::vector<float> hw_, wf_, dhist_[3];  // herzog
  std::vector<float> acc_, lock_, lock_luma_;  // taau
  std::vector<std::vector<float>> cache_;  // drobot: value planes, then depth, then frame count
  std::vector<std::uint32_t> cache_id_;
};

}  // namespace temporal::test
