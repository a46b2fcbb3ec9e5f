// Labels on pictures, drawn with OpenImageIO's render_text (FreeType). OpenImageIO's own font lookup fails on
// Debian 12 (docs/building.md), so the font file is always named explicitly: $TEMPORAL_FONT when set, else
// DejaVu Sans from fonts-dejavu-core.
#pragma once

#include "temporal/core/error.h"
#include "temporal/pictures/picture.h"

#include <string>
#include <string_view>
#include <vector>

namespace temporal {

class Font {
 public:
  // $TEMPORAL_FONT, else /usr/share/fonts/truetype/dejavu/DejaVuSans.ttf (fonts-dejavu-core), else DejaVu Sans
  // elsewhere under /usr/share/fonts. Error (Output) saying what to install when none is found.
  static Expected<Font> find();
  // A given TrueType / OpenType file; Input error when it is missing.
  static Expected<Font> from_file(const std::string& path);

  const std::string& path() const { return path_; }
  // Width of `text` in pixels at `size` (pixels per em), and the height of a line.
  int text_width(std::string_view text, int size) const;
  static int line_height(int size) { return size + size / 3 + 1; }
  // Draws one line of UTF-8 text with its top-left corner near (x, y_top): the baseline sits at
  // y_top + size (clipped to the picture). Internal error when FreeType fails.
  Status draw(Picture& picture, int x, int y_top, std::string_view text, int size, Rgb8 color) const;
  // A picture `width` wide holding the lines, each `size` pixels, on `background`.
  Expected<Picture> label(const std::vector<std::string>& lines, int width, int size, Rgb8 color = kBlack,
                          Rgb8 background = kWhite) const;

 private:
  explicit Font(std::string path) : path_(std::move(path)) {}
  std::string path_;
};

}  // namespace temporal
