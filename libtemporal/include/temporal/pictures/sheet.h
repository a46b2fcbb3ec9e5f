// Contact sheets and grids: pictures laid out in labelled columns (a method per column, the reference first), the
// rectangles of each cell for an HTML image map (each cell links to its EXR), zoomed crops of the regions where
// the methods differ most, and the tiling of video frames.
#pragma once

#include "temporal/core/error.h"
#include "temporal/core/image.h"
#include "temporal/pictures/picture.h"
#include "temporal/pictures/text.h"

#include <optional>
#include <string>
#include <string_view>
#include <vector>

namespace temporal {

// One picture of a sheet with the lines of text above it and what it links to.
struct SheetCell {
  Picture picture;
  std::vector<std::string> caption;  // the first line is drawn larger (the name)
  std::string link;                  // e.g. the EXR it shows; empty: none
  std::string tooltip;               // HTML title of its area
  std::optional<Rgb8> frame;         // a coloured border around the picture (crops: the crop's colour)
};
// A row: one cell per column, nullopt leaves the column empty.
struct SheetRow {
  std::string heading;  // a line above the row ("crop 1: 120,80 48x48, x4"); empty: none
  std::vector<std::optional<SheetCell>> cells;
};
// Where a cell's picture landed, and its link.
struct SheetArea {
  Rect rect;
  std::string link;
  std::string tooltip;
};
struct Sheet {
  Picture picture;
  std::vector<SheetArea> areas;
};

// Lays out rows of cells in columns as wide as the widest picture of the column, with `title` on top, on white.
Expected<Sheet> compose_sheet(const std::string& title, const std::vector<SheetRow>& rows, const Font& font);

// Up to `count` crop_width x crop_height windows with the largest mean of `score` (per pixel; NaN counts as 0),
// searched on a grid of stride max(1, min(crop_width, crop_height) / 4), each overlapping none picked before; the
// best first. Fewer when the picture has no room.
std::vector<Rect> pick_crops(const float* score, int width, int height, int count, int crop_width, int crop_height);
// The side of an automatic square crop: a sixth of the smaller image side, at least 16 pixels (and at most it).
int default_crop_side(int width, int height);
// Parses `x,y,w,h` (pixels, y down); Usage error unless four integers with w, h >= 1.
Expected<Rect> parse_crop(std::string_view text);
// The distinct colours crops are outlined with, by crop number.
Rgb8 crop_color(std::size_t index);

// How `tiles` pictures of image_width x image_height, each under a label `label_height` tall, are tiled into a
// grid no larger than max_width x max_height (shrunk when needed; even total size, as H.264 wants).
struct GridLayout {
  int columns = 1, rows = 1;
  int tile_width = 0, tile_height = 0;  // the picture, without its label
  int label_height = 0;
  int width = 0, height = 0;            // the whole grid
};
GridLayout grid_layout(int tiles, int image_width, int image_height, int label_height, int max_width, int max_height);

}  // namespace temporal
