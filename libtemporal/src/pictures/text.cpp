// Labels (temporal/pictures/text.h): OpenImageIO's render_text into the picture's own bytes.
#include "temporal/pictures/text.h"

#include <OpenImageIO/imagebuf.h>
#include <OpenImageIO/imagebufalgo.h>

#include <cstdlib>
#include <filesystem>

namespace temporal {
namespace fs = std::filesystem;

Expected<Font> Font::find() {
  if (const char* env = std::getenv("TEMPORAL_FONT"); env && *env) return from_file(env);
  const fs::path usual = "/usr/share/fonts/truetype/dejavu/DejaVuSans.ttf";
  std::error_code ec;
  if (fs::is_regular_file(usual, ec)) return Font(usual.string());
  for (fs::recursive_directory_iterator it("/usr/share/fonts", ec), end; !ec && it != end; it.increment(ec))
    if (it->path().filename() == "DejaVuSans.ttf") return Font(it->path().string());
  return Error::output({}, "no font for the picture labels: install fonts-dejavu-core (apt-get install "
                           "fonts-dejavu-core) or point $TEMPORAL_FONT at a .ttf file");
}

Expected<Font> Font::from_file(const std::string& path) {
  std::error_code ec;
  if (!fs::is_regular_file(path, ec)) return Error::input(path, "no such font file ($TEMPORAL_FONT)");
  return Font(path);
}

int Font::text_width(std::string_view text, int size) const {
  if (text.empty()) return 0;
  const OIIO::ROI r = OIIO::ImageBufAlgo::text_size(text, size, path_);
  return r.defined() ? r.width() : int(text.size()) * size * 6 / 10;
}

Status Font::draw(Picture& picture, int x, int y_top, std::string_view text, int size, Rgb8 color) const {
  if (text.empty() || picture.empty()) return {};
  OIIO::ImageSpec spec(picture.width(), picture.height(), 3, OIIO::TypeDesc::UINT8);
  OIIO::ImageBuf buf(spec, picture.bytes());  // wraps the picture: text is composited in place
  const float c[3] = {color.r / 255.0f, color.g / 255.0f, color.b / 255.0f};
  if (!OIIO::ImageBufAlgo::render_text(buf, x, y_top + size * 4 / 5, text, size, path_, c))
    return Error::internal("cannot draw text with the font " + path_ + ": " + buf.geterror());
  return {};
}

Expected<Picture> Font::label(const std::vector<std::string>& lines, int width, int size, Rgb8 color,
                              Rgb8 background) const {
  const int line = line_height(size);
  Picture p(width, std::max(1, int(lines.size()) * line + size / 3), background);
  for (std::size_t i = 0; i < lines.size(); ++i)
    if (auto st = draw(p, size / 3, int(i) * line + size / 6, lines[i], size, color); !st) return st.error();
  return p;
}

}  // namespace temporal
