// Display encoding: scene-linear planes of any layer into a Picture, through the OpenColorIO config of the suite
// (temporal/core/color.h: the built-in config, or $OCIO / --ocio). Values are multiplied by 2^exposure, converted
// from scene-linear Rec.709 to the display colour space (sRGB by default), clamped to [0, 1] and rounded to 8-bit
// code values. NaN / Inf pixels are shown in kNonFiniteColor (magenta).
#pragma once

#include "temporal/io/color_config.h"
#include "temporal/core/error.h"
#include "temporal/core/image.h"
#include "temporal/pictures/picture.h"

#include <span>
#include <string>

namespace temporal {

struct DisplayOptions {
  std::string display = colorspace::kSrgb;  // a colour space of the config (srgb_display, gamma22_display, ...)
  double exposure = 0.0;                    // stops, applied to the scene-linear values before encoding
  std::string ocio;                         // config file; empty: $OCIO if set, else the built-in config
};

class DisplayEncoder {
 public:
  // Loads the config and checks the display space exists (Usage error listing the spaces otherwise) and that the
  // exposure is finite.
  static Expected<DisplayEncoder> create(const DisplayOptions& options);

  // Encodes 1 plane as grey, 2 as (c0, c1, 0), 3 as RGB (more: the first three). Each plane is width * height.
  Expected<Picture> encode(std::span<const float* const> planes, int width, int height) const;
  // The named float channels of `image` (as above).
  Expected<Picture> encode(const Image& image, std::span<const std::string> channels) const;

  const DisplayOptions& options() const { return options_; }

 private:
  DisplayEncoder(ColorConfig config, DisplayOptions options) : config_(std::move(config)), options_(std::move(options)) {}
  ColorConfig config_;
  DisplayOptions options_;
};

}  // namespace temporal
