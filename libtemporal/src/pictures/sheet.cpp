// Contact sheets, crops and grids (temporal/pictures/sheet.h).
#include "temporal/pictures/sheet.h"

#include <algorithm>
#include <charconv>
#include <cmath>

namespace temporal {
namespace {

constexpr int kGap = 8;           // between columns and rows
constexpr int kNameSize = 15;     // first caption line
constexpr int kCaptionSize = 12;  // other caption lines
constexpr int kTitleSize = 18;
constexpr int kBorder = 2;        // coloured frame of a crop cell

int caption_height(const std::vector<std::string>& caption) {
  if (caption.empty()) return 0;
  return Font::line_height(kNameSize) + int(caption.size() - 1) * Font::line_height(kCaptionSize) + 2;
}

}  // namespace

Expected<Sheet> compose_sheet(const std::string& title, const std::vector<SheetRow>& rows, const Font& font) {
  std::size_t columns = 0;
  for (const auto& r : rows) columns = std::max(columns, r.cells.size());
  std::vector<int> col_w(columns, 0);
  std::vector<int> row_caption(rows.size(), 0), row_pic(rows.size(), 0);
  for (std::size_t r = 0; r < rows.size(); ++r)
    for (std::size_t c = 0; c < rows[r].cells.size(); ++c) {
      const auto& cell = rows[r].cells[c];
      if (!cell) continue;
      const int border = cell->frame ? 2 * kBorder : 0;
      col_w[c] = std::max(col_w[c], cell->picture.width() + border);
      for (std::size_t l = 0; l < cell->caption.size(); ++l)  // captions never run into the next column
        col_w[c] = std::max(col_w[c], font.text_width(cell->caption[l], l == 0 ? kNameSize : kCaptionSize) + 4);
      row_caption[r] = std::max(row_caption[r], caption_height(cell->caption));
      row_pic[r] = std::max(row_pic[r], cell->picture.height() + border);
    }
  int width = kGap, height = kGap;
  for (int w : col_w) width += w + kGap;
  const int title_h = title.empty() ? 0 : Font::line_height(kTitleSize) + kGap / 2;
  height += title_h;
  for (std::size_t r = 0; r < rows.size(); ++r)
    height += (rows[r].heading.empty() ? 0 : Font::line_height(kCaptionSize + 1)) + row_caption[r] + row_pic[r] + kGap;
  if (!title.empty()) width = std::max(width, font.text_width(title, kTitleSize) + 2 * kGap);
  for (const auto& r : rows) width = std::max(width, font.text_width(r.heading, kCaptionSize + 1) + 2 * kGap);

  Sheet sheet;
  sheet.picture = Picture(width, height);
  Picture& p = sheet.picture;
  int y = kGap;
  if (!title.empty()) {
    if (auto st = font.draw(p, kGap, y, title, kTitleSize, kBlack); !st) return st.error();
    y += title_h;
  }
  for (std::size_t r = 0; r < rows.size(); ++r) {
    if (!rows[r].heading.empty()) {
      if (auto st = font.draw(p, kGap, y, rows[r].heading, kCaptionSize + 1, {40, 40, 40}); !st) return st.error();
      y += Font::line_height(kCaptionSize + 1);
    }
    int x = kGap;
    for (std::size_t c = 0; c < columns; ++c) {
      if (c < rows[r].cells.size() && rows[r].cells[c]) {
        const SheetCell& cell = *rows[r].cells[c];
        int ty = y;
        for (std::size_t l = 0; l < cell.caption.size(); ++l) {
          const int size = l == 0 ? kNameSize : kCaptionSize;
          if (auto st = font.draw(p, x, ty, cell.caption[l], size, l == 0 ? kBlack : Rgb8{50, 50, 50}); !st)
            return st.error();
          ty += Font::line_height(size);
        }
        const int border = cell.frame ? kBorder : 0;
        const int py = y + row_caption[r];
        if (cell.frame)
          p.outline({x, py, cell.picture.width() + 2 * border, cell.picture.height() + 2 * border}, *cell.frame, kBorder);
        p.paste(cell.picture, x + border, py + border);
        sheet.areas.push_back({{x + border, py + border, cell.picture.width(), cell.picture.height()}, cell.link,
                               cell.tooltip.empty() ? (cell.caption.empty() ? std::string() : cell.caption.front())
                                                    : cell.tooltip});
      }
      x += col_w[c] + kGap;
    }
    y += row_caption[r] + row_pic[r] + kGap;
  }
  return sheet;
}

std::vector<Rect> pick_crops(const float* score, int width, int height, int count, int crop_width, int crop_height) {
  std::vector<Rect> picked;
  if (width < crop_width || height < crop_height || crop_width < 1 || crop_height < 1 || count < 1) return picked;
  // Summed-area table in double: exact enough for any image size.
  const std::size_t W = std::size_t(width) + 1;
  std::vector<double> sat(W * (std::size_t(height) + 1), 0.0);
  for (int y = 0; y < height; ++y) {
    double row = 0.0;
    for (int x = 0; x < width; ++x) {
      const float v = score[std::size_t(y) * std::size_t(width) + std::size_t(x)];
      row += std::isfinite(v) ? double(v) : 0.0;
      sat[(std::size_t(y) + 1) * W + std::size_t(x) + 1] = sat[std::size_t(y) * W + std::size_t(x) + 1] + row;
    }
  }
  auto sum = [&](int x, int y) {
    const std::size_t x0 = std::size_t(x), y0 = std::size_t(y);
    const std::size_t x1 = x0 + std::size_t(crop_width), y1 = y0 + std::size_t(crop_height);
    return sat[y1 * W + x1] - sat[y0 * W + x1] - sat[y1 * W + x0] + sat[y0 * W + x0];
  };
  const int stride = std::max(1, std::min(crop_width, crop_height) / 4);
  auto overlaps = [&](const Rect& a) {
    for (const Rect& b : picked)
      if (a.x < b.x + b.width && b.x < a.x + a.width && a.y < b.y + b.height && b.y < a.y + a.height) return true;
    return false;
  };
  for (int k = 0; k < count; ++k) {
    double best = -1.0;
    Rect best_rect;
    auto consider = [&](int x, int y) {
      const Rect r{x, y, crop_width, crop_height};
      const double s = sum(x, y);
      if (s > best && !overlaps(r)) {
        best = s;
        best_rect = r;
      }
    };
    for (int y = 0; y + crop_height <= height; y += stride) {
      for (int x = 0; x + crop_width <= width; x += stride) consider(x, y);
      consider(width - crop_width, y);  // the right edge, when the stride skips it
    }
    for (int x = 0; x + crop_width <= width; x += stride) consider(x, height - crop_height);  // the bottom edge
    consider(width - crop_width, height - crop_height);
    if (best < 0.0) break;
    picked.push_back(best_rect);
  }
  return picked;
}

int default_crop_side(int width, int height) {
  const int side = std::min(width, height);
  return std::min(side, std::max(16, int(std::lround(side / 6.0))));
}

Expected<Rect> parse_crop(std::string_view text) {
  int v[4];
  const char* p = text.data();
  const char* end = text.data() + text.size();
  for (int i = 0; i < 4; ++i) {
    auto [next, ec] = std::from_chars(p, end, v[i]);
    if (ec != std::errc() || (i < 3 && (next == end || *next != ',')) || (i == 3 && next != end))
      return Error::usage("--crop '" + std::string(text) + "' is not x,y,w,h (four whole numbers of pixels)");
    p = next + 1;
  }
  if (v[2] < 1 || v[3] < 1 || v[0] < 0 || v[1] < 0)
    return Error::usage("--crop '" + std::string(text) + "': x, y must be >= 0 and w, h >= 1");
  return Rect{v[0], v[1], v[2], v[3]};
}

Rgb8 crop_color(std::size_t index) {
  static constexpr Rgb8 colors[] = {{255, 214, 0}, {0, 200, 255}, {80, 230, 80}, {255, 90, 200}};
  return colors[index % (sizeof colors / sizeof colors[0])];
}

GridLayout grid_layout(int tiles, int image_width, int image_height, int label_height, int max_width, int max_height) {
  GridLayout g;
  tiles = std::max(1, tiles);
  g.columns = tiles <= 3 ? tiles : int(std::ceil(std::sqrt(double(tiles))));
  g.rows = (tiles + g.columns - 1) / g.columns;
  g.label_height = label_height;
  const double sx = double(max_width) / double(g.columns * image_width);
  const double sy = double(max_height - g.rows * label_height) / double(g.rows * image_height);
  const double s = std::min({1.0, sx, sy});
  g.tile_width = std::max(2, int(std::floor(image_width * s)));
  g.tile_height = std::max(2, int(std::floor(image_height * s)));
  g.width = g.columns * g.tile_width;
  g.height = g.rows * (g.tile_height + label_height);
  g.width += g.width % 2;
  g.height += g.height % 2;
  return g;
}

}  // namespace temporal
