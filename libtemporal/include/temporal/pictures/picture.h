// Pictures: 8-bit RGB rasters for people to look at (display-encoded frames, heat maps, contact sheets, video
// frames) and their PNG / JPEG files. Data stays in EXR (temporal/io/exr.h); a Picture is what a screen shows,
// already display-encoded (temporal/pictures/display.h), so nothing here knows about colour spaces.
//
// Pixel (x, y) is x to the right, y down from the top-left corner, as everywhere in the suite
// (docs/conventions.md).
#pragma once

#include "temporal/core/error.h"
#include "temporal/core/image.h"

#include <cstdint>
#include <span>
#include <string>
#include <vector>

namespace temporal {

// One display-encoded pixel (8-bit code values).
struct Rgb8 {
  std::uint8_t r = 0, g = 0, b = 0;
  friend bool operator==(const Rgb8&, const Rgb8&) = default;
};

// Colours the pictures use for what is not a pixel value.
inline constexpr Rgb8 kNonFiniteColor{255, 0, 255};  // NaN / Inf input pixel (magenta: no colour map holds it)
inline constexpr Rgb8 kInvalidColor{96, 96, 96};     // excluded from a metric (error.invalid), in heat maps
inline constexpr Rgb8 kWhite{255, 255, 255};
inline constexpr Rgb8 kBlack{0, 0, 0};

class Picture {
 public:
  Picture() = default;
  Picture(int width, int height, Rgb8 fill = kWhite);

  int width() const { return width_; }
  int height() const { return height_; }
  bool empty() const { return width_ <= 0 || height_ <= 0; }
  Rgb8& at(int x, int y) { return pixels_[std::size_t(y) * std::size_t(width_) + std::size_t(x)]; }
  const Rgb8& at(int x, int y) const { return pixels_[std::size_t(y) * std::size_t(width_) + std::size_t(x)]; }
  Rgb8* row(int y) { return pixels_.data() + std::size_t(y) * std::size_t(width_); }
  const Rgb8* row(int y) const { return pixels_.data() + std::size_t(y) * std::size_t(width_); }
  // Interleaved R, G, B bytes, row-major: width * height * 3 of them.
  std::uint8_t* bytes() { return reinterpret_cast<std::uint8_t*>(pixels_.data()); }
  const std::uint8_t* bytes() const { return reinterpret_cast<const std::uint8_t*>(pixels_.data()); }

  // Fills a rectangle (clipped to the picture).
  void fill(const Rect& r, Rgb8 color);
  // Draws the outline of a rectangle, `thickness` pixels wide inside it (clipped).
  void outline(const Rect& r, Rgb8 color, int thickness = 1);
  // Copies `source` with its top-left corner at (x, y) (clipped).
  void paste(const Picture& source, int x, int y);
  // A copy of a rectangle (clipped to the picture).
  Picture crop(const Rect& r) const;
  // Each pixel repeated factor x factor times (zoomed crops keep their pixels sharp). factor >= 1.
  Picture zoomed(int factor) const;
  // Shrunk to width x height by averaging the source pixels each output pixel covers (box filter, in code
  // values); enlarging repeats pixels. width, height >= 1.
  Picture resized(int width, int height) const;

 private:
  int width_ = 0, height_ = 0;
  std::vector<Rgb8> pixels_;
};

// The file formats of write_picture, by extension.
enum class PictureFormat { Png, Jpeg };
// `.png`, `.jpg` or `.jpeg` (any case); a Usage error otherwise.
Expected<PictureFormat> picture_format(const std::string& path);

// Writes `picture` as an 8-bit sRGB PNG, or a JPEG (quality 92), by the extension of `path`, atomically
// (temporary file beside it, then a rename; removed on SIGINT). Creates missing folders. Errors: Usage for
// another extension, Output when it cannot be written.
Status write_picture(const Picture& picture, const std::string& path);
// Reads an 8-bit picture (PNG, JPEG or anything OpenImageIO reads; the first three channels, grey repeated).
Expected<Picture> read_picture(const std::string& path);

}  // namespace temporal
