// The upsampling stage as the sequence runner runs it (temporal/io/runner.h): upsample-st is this stage plus
// its command line. The runner reads each frame (the `--layer` payload and the G-buffer layers of the method),
// handles the frame list, resets and state files; the stage selects the channels, upsamples and fills the
// output header.
#pragma once

#include "temporal/core/stage.h"
#include "temporal/upsample/upsample.h"

#include <optional>
#include <string>
#include <vector>

namespace temporal::upsample {

class UpsampleStage : public FrameStage {
 public:
  // `options` must pass check().
  explicit UpsampleStage(Options options);

  const StageInputs& inputs() const override { return inputs_; }
  // One output per frame, at the output resolution, with the G-buffer's header (camera, clip, frame, time),
  // the input's pass timings plus `temporal:ms:upsample`, and `temporal:method`, `temporal:holePixels`,
  // `temporal:historyPixels`, `temporal:nonFiniteInput`, `temporal:cameraCut` (1 when the history was reset).
  Status process(const StageFrame& frame, std::vector<StageOutput>& out) override;
  bool has_state() const override { return upsampler_.has_state(); }
  Expected<Image> save_state() const override { return upsampler_.save_state(); }
  // Also remembers the frame the state was written after: the first frame of the run must be the next one.
  Status load_state(const Image& state, const std::string& source) override;
  std::string frame_summary() const override;

  // Sums over the frames processed so far.
  const FrameStats& totals() const { return totals_; }

 private:
  Upsampler upsampler_;
  StageInputs inputs_;
  std::optional<int> resume_after_;  // frame of a loaded state, until the first frame is processed
  FrameStats last_, totals_;
};

}  // namespace temporal::upsample
