// Colour: scene-linear Rec.709 is the working space of every tool. Display encodings (sRGB, gamma 2.2) and
// the YCgCo space of the TAA and PHLM filters come from an OpenColorIO config: one built in code by default
// (OCIO 2.1 has no built-in config), or the file named by `--ocio FILE` or `$OCIO`.
//
// Per-pixel inner loops use the inline functions below; their matrices are the ones registered in the
// built-in config, and a test checks that the two agree.
#pragma once

#include "temporal/core/fwd.h"

#include "temporal/core/error.h"

#include <memory>
#include <span>
#include <string>
#include <vector>

namespace temporal {


// Rec.709 / sRGB primaries luminance (ITU-R BT.709), on linear values.
inline float luminance(float r, float g, float b) { return 0.2126f * r + 0.7152f * g + 0.0722f * b; }

// YCgCo (Malvar & Sullivan 2003): Y = R/4 + G/2 + B/4, Cg = -R/4 + G/2 - B/4, Co = R/2 - B/2.
// Exactly invertible: R = Y - Cg + Co, G = Y + Cg, B = Y - Cg - Co.
inline void rgb_to_ycgco(float r, float g, float b, float& y, float& cg, float& co) {
  y = 0.25f * r + 0.5f * g + 0.25f * b;
  cg = -0.25f * r + 0.5f * g - 0.25f * b;
  co = 0.5f * r - 0.5f * b;
}
inline void ycgco_to_rgb(float y, float cg, float co, float& r, float& g, float& b) {
  const float t = y - cg;
  r = t + co;
  g = y + cg;
  b = t - co;
}

// The space the temporal methods clip their histories in, against the box of a 3x3 neighbourhood (Karis 2014: a
// tighter box around chroma; FSR 2 RectifyHistory): each R,G,B triple of a pixel's `channels` values as YCgCo, the
// channels left over (a one-channel payload such as ssao.Y, a fourth channel) as they are. `in` and `out` may be the
// same array. Used by phlm's box test, taa's clipping and taau's rectification.
inline void to_ycgco_box(const float* in, float* out, int channels) {
  int c = 0;
  for (; c + 3 <= channels; c += 3) rgb_to_ycgco(in[c], in[c + 1], in[c + 2], out[c], out[c + 1], out[c + 2]);
  for (; c < channels; ++c) out[c] = in[c];
}
inline void from_ycgco_box(const float* in, float* out, int channels) {
  int c = 0;
  for (; c + 3 <= channels; c += 3) ycgco_to_rgb(in[c], in[c + 1], in[c + 2], out[c], out[c + 1], out[c + 2]);
  for (; c < channels; ++c) out[c] = in[c];
}

// Names of the colour spaces of the built-in config.
namespace colorspace {
inline constexpr const char* kSceneLinear = "lin_rec709";  // role scene_linear
inline constexpr const char* kSrgb = "srgb_display";       // sRGB OETF (IEC 61966-2-1)
inline constexpr const char* kGamma22 = "gamma22_display";  // pure power 1/2.2
inline constexpr const char* kYCgCo = "ycgco";              // linear YCgCo
}  // namespace colorspace

class ColorConfig {
 public:
  // The built-in config.
  static ColorConfig builtin();
  // Loads `path`; an empty path means `$OCIO` if set, else the built-in config.
  static Expected<ColorConfig> load(const std::string& path);

  ColorConfig(ColorConfig&&) noexcept;
  ColorConfig& operator=(ColorConfig&&) noexcept;
  ~ColorConfig();

  // Where the config came from: "built-in" or a file path.
  const std::string& source() const;
  std::vector<std::string> color_spaces() const;
  // Serialised config (YAML), e.g. to save the built-in one for inspection.
  std::string serialize() const;
  // Gamma exponent g of a display space (2.2 for gamma22_display, ~2.2 effective for sRGB), used by
  // formulas that need the display's power law (seed 004 eq. for H').
  Expected<float> display_gamma(const std::string& space) const;

  // Converts three float channels of `image` in place, from one space to another (parallel over rows).
  Status convert(Image& image, std::span<const std::string> rgb_channels, const std::string& from,
                 const std::string& to) const;

 private:
  struct Impl;
  explicit ColorConfig(std::unique_ptr<Impl> impl);
  std::unique_ptr<Impl> impl_;
};

}  // namespace temporal
