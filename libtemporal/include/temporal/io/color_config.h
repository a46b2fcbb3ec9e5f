// Colour management through OpenColorIO: display encodings (sRGB, gamma 2.2) and the YCgCo space of the TAA and
// PHLM filters come from an OpenColorIO config: one built in code by default (OCIO 2.1 has no built-in config),
// or the file named by `--ocio FILE` or `$OCIO`. The per-pixel formulas the kernels use are in
// temporal/core/color.h.
#pragma once

#include "temporal/core/color.h"
#include "temporal/core/error.h"
#include "temporal/core/fwd.h"

#include <memory>
#include <span>
#include <string>
#include <vector>

namespace temporal {

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

// The display gamma of `space` in the config at `config_path` (empty: $OCIO, else the built-in config): one call
// for a caller that needs nothing else of the config (morph-120hz --display).
Expected<float> load_display_gamma(const std::string& space, const std::string& config_path);

}  // namespace temporal
