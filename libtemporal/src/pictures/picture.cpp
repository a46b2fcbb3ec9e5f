// 8-bit RGB pictures and their files (temporal/pictures/picture.h), written through OpenImageIO.
#include "temporal/pictures/picture.h"

#include "temporal/io/atomic_file.h"

#include <OpenImageIO/imageio.h>

#include <algorithm>
#include <cctype>
#include <filesystem>

namespace temporal {
namespace {

// The part of `r` inside a width x height raster.
Rect clip(const Rect& r, int width, int height) {
  const int x0 = std::max(0, r.x), y0 = std::max(0, r.y);
  const int x1 = std::min(width, r.x + r.width), y1 = std::min(height, r.y + r.height);
  return {x0, y0, std::max(0, x1 - x0), std::max(0, y1 - y0)};
}

}  // namespace

Picture::Picture(int width, int height, Rgb8 fill)
    : width_(std::max(0, width)), height_(std::max(0, height)),
      pixels_(std::size_t(width_) * std::size_t(height_), fill) {}

void Picture::fill(const Rect& r, Rgb8 color) {
  const Rect c = clip(r, width_, height_);
  for (int y = c.y; y < c.y + c.height; ++y) std::fill(row(y) + c.x, row(y) + c.x + c.width, color);
}

void Picture::outline(const Rect& r, Rgb8 color, int thickness) {
  const int t = std::max(1, std::min({thickness, r.width / 2 + 1, r.height / 2 + 1}));
  fill({r.x, r.y, r.width, t}, color);
  fill({r.x, r.y + r.height - t, r.width, t}, color);
  fill({r.x, r.y, t, r.height}, color);
  fill({r.x + r.width - t, r.y, t, r.height}, color);
}

void Picture::paste(const Picture& source, int x, int y) {
  const Rect c = clip({x, y, source.width_, source.height_}, width_, height_);
  for (int yy = c.y; yy < c.y + c.height; ++yy) {
    const Rgb8* from = source.row(yy - y) + (c.x - x);
    std::copy(from, from + c.width, row(yy) + c.x);
  }
}

Picture Picture::crop(const Rect& r) const {
  const Rect c = clip(r, width_, height_);
  Picture out(c.width, c.height);
  for (int y = 0; y < c.height; ++y) std::copy(row(c.y + y) + c.x, row(c.y + y) + c.x + c.width, out.row(y));
  return out;
}

Picture Picture::zoomed(int factor) const {
  factor = std::max(1, factor);
  Picture out(width_ * factor, height_ * factor);
  for (int y = 0; y < out.height_; ++y) {
    const Rgb8* from = row(y / factor);
    Rgb8* to = out.row(y);
    for (int x = 0; x < out.width_; ++x) to[x] = from[x / factor];
  }
  return out;
}

Picture Picture::resized(int width, int height) const {
  width = std::max(1, width);
  height = std::max(1, height);
  Picture out(width, height);
  if (empty()) return out;
  for (int y = 0; y < height; ++y) {
    // Source rows [y0, y1) that output row y covers (at least one).
    const int y0 = int(std::int64_t(y) * height_ / height);
    const int y1 = std::max(y0 + 1, int(std::int64_t(y + 1) * height_ / height));
    for (int x = 0; x < width; ++x) {
      const int x0 = int(std::int64_t(x) * width_ / width);
      const int x1 = std::max(x0 + 1, int(std::int64_t(x + 1) * width_ / width));
      unsigned sum[3] = {0, 0, 0};
      for (int sy = y0; sy < y1; ++sy)
        for (int sx = x0; sx < x1; ++sx) {
          const Rgb8& p = at(sx, sy);
          sum[0] += p.r;
          sum[1] += p.g;
          sum[2] += p.b;
        }
      const unsigned n = unsigned((y1 - y0) * (x1 - x0));
      out.at(x, y) = {std::uint8_t((sum[0] + n / 2) / n), std::uint8_t((sum[1] + n / 2) / n),
                      std::uint8_t((sum[2] + n / 2) / n)};
    }
  }
  return out;
}

Expected<PictureFormat> picture_format(const std::string& path) {
  std::string ext = std::filesystem::path(path).extension().string();
  for (char& c : ext) c = char(std::tolower(static_cast<unsigned char>(c)));
  if (ext == ".png") return PictureFormat::Png;
  if (ext == ".jpg" || ext == ".jpeg") return PictureFormat::Jpeg;
  return Error::usage("'" + path + "': pictures are written as .png or .jpg");
}

Status write_picture(const Picture& picture, const std::string& path) {
  auto format = picture_format(path);
  if (!format) return format.error();
  if (picture.empty()) return Error::internal("write_picture: empty picture for " + path);
  TemporaryFile tmp(path);
  auto out = OIIO::ImageOutput::create(tmp.path());
  if (!out) return Error::output(path, "no PNG/JPEG writer in OpenImageIO: " + OIIO::geterror());
  OIIO::ImageSpec spec(picture.width(), picture.height(), 3, OIIO::TypeDesc::UINT8);
  if (*format == PictureFormat::Jpeg) spec.attribute("Compression", "jpeg:92");
  spec.attribute("oiio:ColorSpace", "sRGB");
  if (!out->open(tmp.path(), spec) || !out->write_image(OIIO::TypeDesc::UINT8, picture.bytes()) || !out->close())
    return Error::output(path, "cannot write the picture (" + out->geterror() + "); is the folder writable?");
  return tmp.commit();
}

Expected<Picture> read_picture(const std::string& path) {
  auto in = OIIO::ImageInput::open(path);
  if (!in) return Error::input(path, "cannot read the picture: " + OIIO::geterror());
  const OIIO::ImageSpec& spec = in->spec();
  std::vector<std::uint8_t> data(std::size_t(spec.width) * std::size_t(spec.height) * std::size_t(spec.nchannels));
  if (!in->read_image(0, 0, 0, spec.nchannels, OIIO::TypeDesc::UINT8, data.data()))
    return Error::input(path, "cannot read the picture: " + in->geterror());
  Picture p(spec.width, spec.height);
  const std::size_t nc = std::size_t(spec.nchannels);
  for (int y = 0; y < spec.height; ++y)
    for (int x = 0; x < spec.width; ++x) {
      const std::uint8_t* s = &data[(std::size_t(y) * std::size_t(spec.width) + std::size_t(x)) * nc];
      p.at(x, y) = nc >= 3 ? Rgb8{s[0], s[1], s[2]} : Rgb8{s[0], s[0], s[0]};
    }
  return p;
}

}  // namespace temporal
