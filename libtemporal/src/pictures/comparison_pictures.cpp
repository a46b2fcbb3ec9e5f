// The pictures of a comparison (temporal/pictures/comparison_pictures.h). Per frame (observe): display-encode the
// reference and each test once, write the --png files, append the profile lines, send the video frame, and keep
// the contact sheet's frame. After the run (finish): crops, the sheet, the maps of its frame, the profiles.
//
// Picture outputs never stop the comparison: a failure is kept (errors) and that output is dropped, so the
// metrics, CSV and JSON are still written and compare exits 4 (docs/compare.md).
#include "temporal/pictures/comparison_pictures.h"

#include "temporal/io/exr.h"
#include "temporal/core/sequence.h"
#include "temporal/pictures/colormap.h"
#include "temporal/pictures/sheet.h"
#include "temporal/pictures/text.h"
#include "temporal/pictures/video.h"
#include "temporal/pictures/visualize.h"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <filesystem>

namespace temporal {
namespace {

namespace fs = std::filesystem;

constexpr int kVideoLabel = 20;  // label strip above each video tile
constexpr int kVideoMaxWidth = 1920, kVideoMaxHeight = 1080;

std::string safe_name(const std::string& name) {
  std::string out;
  for (char c : name) out += (std::isalnum(static_cast<unsigned char>(c)) || c == '-' || c == '_' || c == '.') ? c : '_';
  return out.empty() ? std::string("test") : out;
}

std::vector<const float*> planes_of(const Image& image, std::span<const std::string> channels) {
  std::vector<const float*> planes;
  for (const auto& c : channels) planes.push_back(image.plane(c));
  return planes;
}

}  // namespace

std::string metric_label(std::string_view metric) {
  const MetricDefinition* d = find_metric(metric);
  return d && !d->label.empty() ? d->label : std::string(metric);
}

std::string metric_text(std::string_view metric, double value) {
  const MetricDefinition* d = find_metric(metric);
  return metric_label(metric) + " " + format_number(value, 4) + (d && std::isfinite(value) ? unit_suffix(*d) : std::string());
}

struct ComparisonPictures::Impl {
  PictureOptions o;
  const ProtectedInputs* inputs = nullptr;
  std::optional<DisplayEncoder> encoder;
  std::optional<Font> font;
  std::string ext;  // ".png" / ".jpg" of the --png files
  bool png_on = false, report_on = false;
  PictureProducts products;

  // Set at the first frame.
  int width = 0, height = 0;
  bool started = false;
  float png_error_high = 1.0f;  // the --png error maps' upper end (from the first frame)
  std::vector<std::string> profile_channels;
  std::vector<TemporalProfile> profiles;  // reference first, then the tests
  std::vector<std::string> names;         // "reference", then the tests
  std::vector<std::string> first_paths;   // each sequence's first frame (the profiles' EXR links)
  std::optional<VideoWriter> video;
  GridLayout grid;
  std::vector<Picture> video_labels;
  int first_frame = 0, last_frame = 0;
  std::size_t frames_seen = 0;

  // The contact sheet's frame.
  struct CapturedTest {
    std::string name, path;
    Picture picture;
    FrameMetrics metrics;
    std::optional<Image> maps;  // error.* of the frame (for the maps' EXR and heat maps)
  };
  struct Captured {
    int frame = 0;
    Picture reference;
    std::string reference_path, gbuffer_path;
    std::vector<CapturedTest> tests;
    std::vector<std::pair<std::string, Picture>> gbuffer;  // (what, picture)
    std::string gbuffer_note;
  };
  std::optional<Captured> captured;

  void fail(const Error& e) { products.errors.push_back(e); }

  Status guard(const std::string& path, const char* option) const {
    return inputs ? inputs->check(path, option) : Status::ok();
  }
  Status write(const Picture& p, const std::string& path, const char* option) {
    if (auto st = guard(path, option); !st) return st;
    if (auto st = write_picture(p, path); !st) return st;
    products.written.push_back(path);
    return {};
  }
  Status write_exr_file(const Image& image, const std::string& path, const char* option) {
    if (auto st = guard(path, option); !st) return st;
    if (auto st = write_exr(path, image); !st) return st;
    products.written.push_back(path);
    return {};
  }
  // `path` relative to the report folder (links of the page).
  std::string rel(const std::string& path) const {
    std::error_code ec;
    const fs::path r = fs::relative(fs::absolute(path, ec), fs::absolute(o.report_dir, ec), ec);
    return ec || r.empty() ? fs::absolute(path).generic_string() : r.generic_string();
  }
  std::string in_report(const std::string& relative) const { return (fs::path(o.report_dir) / relative).string(); }

  Status start(const ComparedFrame& cf);
  Status observe(const ComparedFrame& cf);
  Expected<std::vector<std::pair<std::string, Picture>>> gbuffer_pictures(const Image& g, std::string* note) const;
  Expected<Picture> heat(const Image& maps, const char* channel, Colormap map, float high, const std::string& label) const;
  Status video_frame(const ComparedFrame& cf, const Picture& ref, const std::vector<Picture>& tests);
  Expected<PictureProducts> finish(const ComparisonReport& report);
  Status finish_sheet(const ComparisonReport& report);
  Expected<std::vector<Rect>> sheet_crops(bool flip) const;
  float sheet_error_high() const;
  static std::vector<std::string> sheet_caption(const ComparisonReport& report, const CapturedTest& t);
  Expected<std::vector<std::string>> write_sheet_maps();
  // The report's sections of single maps (FLIP, error) and of the G-buffer pictures, after the sheet.
  Status report_map_sections(const ComparisonReport& report, bool flip, float error_high,
                             const std::vector<std::string>& map_links);
  Status finish_profiles(const ComparisonReport& report);
};

ComparisonPictures::ComparisonPictures(std::unique_ptr<Impl> impl) : impl_(std::move(impl)) {}
ComparisonPictures::~ComparisonPictures() = default;

Expected<std::unique_ptr<ComparisonPictures>> ComparisonPictures::create(const PictureOptions& options,
                                                                         const ComparisonSetup& setup,
                                                                         const ProtectedInputs* inputs) {
  auto impl = std::make_unique<Impl>();
  impl->o = options;
  impl->inputs = inputs;
  impl->png_on = !options.png_dir.empty();
  impl->report_on = !options.report_dir.empty();
  if (options.png_format != "png" && options.png_format != "jpg")
    return Error::usage("--png-format '" + options.png_format + "': use png or jpg");
  impl->ext = "." + options.png_format;
  for (const auto& c : options.crops)
    if (c.width < 1 || c.height < 1) return Error::usage("a --crop needs a width and height of at least 1");
  if (options.max_tile_width < 16) return Error::usage("the sheet's tile width must be at least 16 pixels");
  auto encoder = DisplayEncoder::create(options.display);
  if (!encoder) return encoder.error();
  impl->encoder.emplace(std::move(*encoder));
  auto font = Font::find();
  if (!font) return font.error();
  impl->font.emplace(std::move(*font));
  (void)setup;
  return std::unique_ptr<ComparisonPictures>(new ComparisonPictures(std::move(impl)));
}

void ComparisonPictures::attach(ComparisonHooks& hooks) {
  hooks.keep_maps = true;
  for (const char* layer : {"depth", "N", "id"})
    if (std::find(hooks.gbuffer_layers.begin(), hooks.gbuffer_layers.end(), layer) == hooks.gbuffer_layers.end())
      hooks.gbuffer_layers.push_back(layer);
  hooks.frame = [impl = impl_.get()](const ComparedFrame& cf) { return impl->observe(cf); };
}

Expected<PictureProducts> ComparisonPictures::finish(const ComparisonReport& report) { return impl_->finish(report); }

Status ComparisonPictures::Impl::start(const ComparedFrame& cf) {
  started = true;
  width = cf.reference->width();
  height = cf.reference->height();
  first_frame = cf.frame;
  names.push_back("reference");
  first_paths.push_back(cf.reference_path);
  for (const auto& t : cf.tests) {
    names.push_back(t.name);
    first_paths.push_back(t.path);
  }
  const std::size_t nc = cf.reference_channels.size();
  profile_channels = nc == 3 ? std::vector<std::string>{"R", "G", "B"}
                     : nc == 1 ? std::vector<std::string>{"Y"}
                               : std::vector<std::string>(cf.reference_channels.begin(), cf.reference_channels.end());
  if (auto line = o.profile.resolve(width, height); !line) return line.error();  // a usage error stops the run
  // --crop is checked here, at the first frame, not when the sheet is drawn after the whole comparison. In 64 bits:
  // x + w of --crop 60,60,2147483647,2147483647 overflows an int (and then passed, issue 26 item 8).
  for (const Rect& r : o.crops)
    if (std::int64_t(r.x) + r.width > width || std::int64_t(r.y) + r.height > height)
      return Error::usage("--crop " + std::to_string(r.x) + "," + std::to_string(r.y) + "," + std::to_string(r.width) +
                          "," + std::to_string(r.height) + " does not fit in the " + std::to_string(width) + "x" +
                          std::to_string(height) + " image");
  for (std::size_t i = 0; i < names.size(); ++i) profiles.emplace_back(o.profile, profile_channels);

  // --png error maps: one range for every frame and method, from the first frame (values above it saturate).
  std::vector<float> all;
  for (const auto& t : cf.tests) {
    const float* e = t.maps ? t.maps->plane("error.Y") : nullptr;
    const float* inv = t.maps ? t.maps->plane("error.invalid") : nullptr;
    if (!e) continue;
    for (std::size_t i = 0; i < t.maps->pixel_count(); ++i)
      if (!inv || inv[i] <= 0.5f) all.push_back(e[i]);
  }
  png_error_high = nice_ceiling(plane_quantile(all.data(), all.size(), 0.99));

  if (report_on && o.video) {
    grid = grid_layout(int(names.size()), width, height, kVideoLabel, kVideoMaxWidth, kVideoMaxHeight);
    for (const auto& n : names) {
      auto label = font->label({n}, grid.tile_width, 13, kWhite, {40, 40, 40});
      if (!label) return label.error();
      video_labels.push_back(std::move(*label));
    }
    const double fps = cf.reference->metadata().fps.value_or(30.0);
    products.video_caption = std::to_string(grid.columns) + " x " + std::to_string(grid.rows) + " grid, " +
                             std::to_string(grid.width) + "x" + std::to_string(grid.height) + ", H.264 at " +
                             format_number(fps, 4) + " frames/s (the reference's temporal:fps" +
                             (cf.reference->metadata().fps ? ")" : ", absent: 30 assumed)") + ".";
    VideoOptions vo;
    vo.fps = fps;
    const std::string path = in_report("video.mp4");
    if (auto st = guard(path, "--report"); !st) return st;
    auto v = VideoWriter::open(path, grid.width, grid.height, vo);
    if (!v) fail(v.error());  // no ffmpeg: the report goes on without its video
    else video.emplace(std::move(*v));
  }
  return {};
}

Expected<std::vector<std::pair<std::string, Picture>>> ComparisonPictures::Impl::gbuffer_pictures(const Image& g,
                                                                                                  std::string* note) const {
  std::vector<std::pair<std::string, Picture>> out;
  const int w = g.width(), h = g.height();
  if (const float* z = g.plane("depth.Z")) out.emplace_back("depth", depth_picture(z, w, h, g.metadata().far_clip.value_or(0.0f)));
  if (g.plane("N.X") && g.plane("N.Y") && g.plane("N.Z"))
    out.emplace_back("normal", normal_picture(g.plane("N.X"), g.plane("N.Y"), g.plane("N.Z"), w, h));
  if (g.plane("motion.X") && g.plane("motion.Y")) {
    float scale = 0.0f;
    out.emplace_back("motion", motion_picture(g.plane("motion.X"), g.plane("motion.Y"), w, h, 0.0f, &scale));
    if (note) *note = "motion: hue = direction, saturation = length, full at " + format_number(scale, 3) + " pixels";
  }
  if (const std::uint32_t* id = g.uint_plane("id")) out.emplace_back("id", id_picture(id, w, h));
  return out;
}

Expected<Picture> ComparisonPictures::Impl::heat(const Image& maps, const char* channel, Colormap map, float high,
                                                 const std::string& label) const {
  const float* v = maps.plane(channel);
  if (!v) return Error::internal(std::string("no ") + channel + " in the error maps");
  Picture p = heat_map(v, maps.plane("error.invalid"), maps.width(), maps.height(), map, 0.0f, high);
  auto bar = colour_bar(map, 0.0f, high, label, std::max(p.width(), 120), *font);
  if (!bar) return bar.error();
  return stacked(p, *bar);
}

Status ComparisonPictures::Impl::video_frame(const ComparedFrame& cf, const Picture& ref, const std::vector<Picture>& tests) {
  Picture frame(grid.width, grid.height, {40, 40, 40});
  for (std::size_t i = 0; i < names.size(); ++i) {
    const int x = int(i % std::size_t(grid.columns)) * grid.tile_width;
    const int y = int(i / std::size_t(grid.columns)) * (grid.tile_height + grid.label_height);
    if (i == 0) {  // the reference's label carries the frame number
      auto label = font->label({"reference   frame " + std::to_string(cf.frame)}, grid.tile_width, 13, kWhite, {40, 40, 40});
      if (!label) return label.error();
      frame.paste(*label, x, y);
    } else {
      frame.paste(video_labels[i], x, y);
    }
    const Picture& p = i == 0 ? ref : tests[i - 1];
    if (p.width() == grid.tile_width && p.height() == grid.tile_height) frame.paste(p, x, y + grid.label_height);
    else frame.paste(p.resized(grid.tile_width, grid.tile_height), x, y + grid.label_height);
  }
  if (video->frames() == 0) {
    const std::string poster = in_report("pictures/video-poster.png");
    if (auto st = write(frame, poster, "--report"); !st) return st;
    products.video_poster = "pictures/video-poster.png";
  }
  return video->add(frame);
}

Status ComparisonPictures::Impl::observe(const ComparedFrame& cf) {
  if (!started)
    if (auto st = start(cf); !st) return st;
  ++frames_seen;
  last_frame = cf.frame;
  // Profiles: the compared channels of each sequence, in the reference's order.
  if (auto st = profiles[0].add(planes_of(*cf.reference, cf.reference_channels), width, height); !st) return st;
  for (std::size_t i = 0; i < cf.tests.size(); ++i)
    if (cf.tests[i].image)
      if (auto st = profiles[i + 1].add(planes_of(*cf.tests[i].image, cf.tests[i].channels), width, height); !st) return st;

  const bool capture = o.sheet_frame ? cf.frame == *o.sheet_frame : cf.index + 1 == cf.count;
  if (!png_on && !video && !capture) return {};

  auto ref = encoder->encode(*cf.reference, cf.reference_channels);
  if (!ref) return ref.error();
  std::vector<Picture> tests;
  for (const auto& t : cf.tests) {
    auto p = encoder->encode(*t.image, t.channels);
    if (!p) return p.error();
    tests.push_back(std::move(*p));
  }

  if (png_on) {
    auto write_all = [&]() -> Status {
      const std::string d = frame_digits(cf.frame);
      if (auto st = write(*ref, (fs::path(o.png_dir) / ("reference." + d + ext)).string(), "--png"); !st) return st;
      for (std::size_t i = 0; i < cf.tests.size(); ++i) {
        const auto& t = cf.tests[i];
        const std::string base = (fs::path(o.png_dir) / safe_name(t.name)).string();
        if (auto st = write(tests[i], base + "." + d + ext, "--png"); !st) return st;
        if (!t.maps) continue;
        if (t.maps->plane("error.flip")) {
          auto h = heat(*t.maps, "error.flip", Colormap::Magma, 1.0f, "FLIP (magma)");
          if (!h) return h.error();
          if (auto st = write(*h, base + "-flip." + d + ext, "--png"); !st) return st;
        }
        auto h = heat(*t.maps, "error.Y", Colormap::Inferno, png_error_high, "|error| of luminance (inferno)");
        if (!h) return h.error();
        if (auto st = write(*h, base + "-error." + d + ext, "--png"); !st) return st;
      }
      if (cf.gbuffer) {
        auto g = gbuffer_pictures(*cf.gbuffer, nullptr);
        if (!g) return g.error();
        for (const auto& [what, p] : *g)
          if (auto st = write(p, (fs::path(o.png_dir) / ("gbuffer-" + what + "." + d + ext)).string(), "--png"); !st)
            return st;
      }
      return {};
    };
    if (auto st = write_all(); !st) {
      if (st.error().kind == ErrorKind::Usage) return st;  // an output that would replace an input
      fail(st.error());
      png_on = false;  // one message, not one per frame
    }
  }
  if (video) {
    if (auto st = video_frame(cf, *ref, tests); !st) {
      fail(st.error());
      video.reset();
    }
  }
  if (capture) {
    Captured c;
    c.frame = cf.frame;
    c.reference = *ref;
    c.reference_path = cf.reference_path;
    for (std::size_t i = 0; i < cf.tests.size(); ++i) {
      const auto& t = cf.tests[i];
      CapturedTest ct{t.name, t.path, std::move(tests[i]), t.metrics ? *t.metrics : FrameMetrics{}, {}};
      if (t.maps) ct.maps = *t.maps;
      c.tests.push_back(std::move(ct));
    }
    if (cf.gbuffer) {
      c.gbuffer_path = cf.gbuffer_path;
      auto g = gbuffer_pictures(*cf.gbuffer, &c.gbuffer_note);
      if (!g) return g.error();
      c.gbuffer = std::move(*g);
    }
    captured = std::move(c);
  }
  return {};
}

Expected<PictureProducts> ComparisonPictures::Impl::finish(const ComparisonReport& report) {
  if (!captured) {
    if (o.sheet_frame)
      return Error::usage("--sheet-frame " + std::to_string(*o.sheet_frame) + " is not one of the compared frames (" +
                          std::to_string(report.frames.empty() ? 0 : report.frames.front()) + "-" +
                          std::to_string(report.frames.empty() ? 0 : report.frames.back()) + ")");
    return Error::internal("no frame was kept for the contact sheet");
  }
  if (auto st = finish_sheet(report); !st) {
    if (st.error().kind == ErrorKind::Usage) return st.error();
    fail(st.error());
  }
  if (auto st = finish_profiles(report); !st) {
    if (st.error().kind == ErrorKind::Usage) return st.error();
    fail(st.error());
  }
  if (video) {
    if (auto st = video->finish(); !st) fail(st.error());
    else {
      products.video = "video.mp4";
      products.video_width = grid.width;
      products.video_height = grid.height;
      products.written.push_back(in_report("video.mp4"));
    }
    video.reset();
  }
  return std::move(products);
}

// The crops of the contact sheet: given (--crop, checked against the image), or where the methods differ most
// (the sum over the tests of FLIP, else of the error).
Expected<std::vector<Rect>> ComparisonPictures::Impl::sheet_crops(bool flip) const {
  const Captured& c = *captured;
  std::vector<Rect> crops;
  for (const Rect& r : o.crops) crops.push_back(r);  // checked against the image at the first frame (start)
  if (!crops.empty()) return crops;
  std::vector<float> score(std::size_t(width) * std::size_t(height), 0.0f);
  for (const auto& t : c.tests) {
    if (!t.maps) continue;
    const float* v = t.maps->plane(flip ? "error.flip" : "error.Y");
    const float* inv = t.maps->plane("error.invalid");
    if (!v) continue;
    for (std::size_t i = 0; i < score.size(); ++i)
      if (!(inv && inv[i] > 0.5f) && std::isfinite(v[i])) score[i] += v[i];
  }
  const int side = default_crop_side(width, height);
  return pick_crops(score.data(), width, height, o.picked_crops, side, side);
}

// The top of the error maps' range: a round number above the 99th percentile of error.Y over every test's valid
// pixels.
float ComparisonPictures::Impl::sheet_error_high() const {
  std::vector<float> error_all;
  for (const auto& t : captured->tests) {
    const float* e = t.maps ? t.maps->plane("error.Y") : nullptr;
    const float* inv = t.maps ? t.maps->plane("error.invalid") : nullptr;
    if (e)
      for (std::size_t i = 0; i < t.maps->pixel_count(); ++i)
        if (!(inv && inv[i] > 0.5f)) error_all.push_back(e[i]);
  }
  return nice_ceiling(plane_quantile(error_all.data(), error_all.size(), 0.99));
}

// A test's caption on the sheet: its name, then its metrics two per line (those the registry puts on sheets).
std::vector<std::string> ComparisonPictures::Impl::sheet_caption(const ComparisonReport& report,
                                                                 const CapturedTest& t) {
  std::vector<std::string> lines = {t.name};
  std::string line;
  int on_line = 0;
  for (const auto& m : report.metrics) {
    if (const MetricDefinition* d = find_metric(m); d && !d->on_sheet) continue;
    const double v = t.metrics.value(m);
    if (std::isnan(v)) continue;
    line += (on_line ? "  " : "") + metric_text(m, v);
    if (++on_line == 2) {
      lines.push_back(line);
      line.clear();
      on_line = 0;
    }
  }
  if (!line.empty()) lines.push_back(line);
  return lines;
}

// Writes each test's error maps of the sheet's frame as maps/NAME.####.exr in the report (with --report) and
// returns their links (empty without).
Expected<std::vector<std::string>> ComparisonPictures::Impl::write_sheet_maps() {
  const Captured& c = *captured;
  std::vector<std::string> map_links;
  for (const auto& t : c.tests) {
    std::string link;
    if (report_on && t.maps) {
      Image exr = *t.maps;
      exr.metadata().frame = c.frame;
      exr.metadata().extra["reference"] = c.reference_path;
      exr.metadata().extra["test"] = t.path;
      const std::string rel_path = "maps/" + safe_name(t.name) + "." + frame_digits(c.frame) + ".exr";
      if (auto st = write_exr_file(exr, in_report(rel_path), "--report"); !st) return st.error();
      link = rel_path;
    }
    map_links.push_back(link);
  }
  return map_links;
}

Status ComparisonPictures::Impl::finish_sheet(const ComparisonReport& report) {
  const Captured& c = *captured;
  const bool flip = !c.tests.empty() && c.tests.front().maps && c.tests.front().maps->plane("error.flip");

  auto picked = sheet_crops(flip);
  if (!picked) return picked.error();
  const std::vector<Rect> crops = std::move(*picked);
  const float error_high = sheet_error_high();

  // Tiles: shrunk to max_tile_width, the crops outlined.
  const double scale = std::min(1.0, double(o.max_tile_width) / double(width));
  const int tile_w = std::max(1, int(std::lround(width * scale))), tile_h = std::max(1, int(std::lround(height * scale)));
  auto tile = [&](const Picture& p, bool outlines) {
    Picture t = scale < 1.0 ? p.resized(tile_w, tile_h) : p;
    if (outlines)
      for (std::size_t k = 0; k < crops.size(); ++k) {
        const Rect& r = crops[k];
        t.outline({int(std::floor(r.x * scale)), int(std::floor(r.y * scale)), std::max(3, int(std::lround(r.width * scale))),
                   std::max(3, int(std::lround(r.height * scale)))},
                  crop_color(k), 2);
      }
    return t;
  };
  const bool links = report_on;
  std::vector<SheetRow> rows(1);
  const std::string sheet_frame = "frame " + std::to_string(c.frame);
  rows[0].cells.push_back(SheetCell{tile(c.reference, true), {"reference", sheet_frame, "layer " + report.reference_layer},
                                    links ? rel(c.reference_path) : std::string(), "reference, " + c.reference_path, {}});
  for (const auto& t : c.tests) {
    const std::vector<std::string> lines = sheet_caption(report, t);
    rows[0].cells.push_back(SheetCell{tile(t.picture, true), lines, links ? rel(t.path) : std::string(), t.name + ", " + t.path, {}});
  }
  // The heat maps of the frame: FLIP (magma, 0..1, the FLIP paper's) or the error of luminance (inferno).
  SheetRow maps_row;
  maps_row.heading = flip ? "FLIP per pixel (magma, 0 = identical ... 1)"
                          : "|error| of luminance per pixel (inferno, 0 ... " + format_number(error_high, 3) + ")";
  auto written_maps = write_sheet_maps();
  if (!written_maps) return written_maps.error();
  const std::vector<std::string>& map_links = *written_maps;
  {
    auto bar = colour_bar(flip ? Colormap::Magma : Colormap::Inferno, 0.0f, flip ? 1.0f : error_high,
                          flip ? "FLIP" : "|error| of luminance", tile_w, *font);
    if (!bar) return bar.error();
    maps_row.cells.push_back(SheetCell{*bar, {"colour bar"}, {}, {}, {}});
  }
  for (std::size_t i = 0; i < c.tests.size(); ++i) {
    const auto& t = c.tests[i];
    if (!t.maps) {
      maps_row.cells.emplace_back();
      continue;
    }
    const float* v = t.maps->plane(flip ? "error.flip" : "error.Y");
    Picture p = heat_map(v, t.maps->plane("error.invalid"), width, height, flip ? Colormap::Magma : Colormap::Inferno, 0.0f,
                         flip ? 1.0f : error_high);
    maps_row.cells.push_back(SheetCell{tile(p, false), {t.name + (flip ? " FLIP" : " |error|")}, map_links[i],
                                       t.name + ": error maps EXR", {}});
  }
  rows.push_back(std::move(maps_row));
  // The zoomed crops: as large as a tile allows, pixels kept sharp.
  for (std::size_t k = 0; k < crops.size(); ++k) {
    const Rect& r = crops[k];
    const int zoom = std::max(1, std::min(tile_w / r.width, tile_h / r.height));
    SheetRow row;
    row.heading = "crop " + std::to_string(k + 1) + ": x " + std::to_string(r.x) + ", y " + std::to_string(r.y) + ", " +
                  std::to_string(r.width) + "x" + std::to_string(r.height) + " pixels, shown x" + std::to_string(zoom) +
                  (o.crops.empty() ? (flip ? " (picked: largest FLIP)" : " (picked: largest error)") : "");
    row.cells.push_back(SheetCell{c.reference.crop(r).zoomed(zoom), {}, links ? rel(c.reference_path) : std::string(),
                                  "reference, crop " + std::to_string(k + 1), crop_color(k)});
    for (const auto& t : c.tests)
      row.cells.push_back(SheetCell{t.picture.crop(r).zoomed(zoom), {}, links ? rel(t.path) : std::string(),
                                    t.name + ", crop " + std::to_string(k + 1), crop_color(k)});
    rows.push_back(std::move(row));
  }
  const std::string title = (o.title.empty() ? std::string() : o.title + ": ") + "frame " + std::to_string(c.frame) +
                            " of " + std::to_string(report.frames.size()) + " compared";
  auto sheet = compose_sheet(title, rows, *font);
  if (!sheet) return sheet.error();
  if (png_on)
    if (auto st = write(sheet->picture, (fs::path(o.png_dir) / ("sheet." + frame_digits(c.frame) + ext)).string(), "--png"); !st)
      return st;
  if (!report_on) return {};
  if (auto st = write(sheet->picture, in_report("pictures/sheet.png"), "--report"); !st) return st;

  ReportSection s;
  s.id = "sheet";
  s.heading = "Contact sheet, frame " + std::to_string(c.frame);
  s.text = (o.sheet_frame ? std::string("The frame asked for (--sheet-frame).") : std::string("The last compared frame (--sheet-frame picks another).")) +
           " Display encoding: " + o.display.display + (o.display.exposure != 0.0 ? ", exposure " + format_number(o.display.exposure, 3) + " stops" : std::string()) +
           "; magenta pixels are NaN or Inf in the file.";
  s.images.push_back({"pictures/sheet.png", {}, "Every method beside the reference with this frame's metrics, its " +
                      std::string(flip ? "FLIP" : "error") + " map and zoomed crops.", "contact sheet", "sheet",
                      sheet->picture.width(), sheet->picture.height(), sheet->areas});
  products.sections.push_back(std::move(s));

  return report_map_sections(report, flip, error_high, map_links);
}

Status ComparisonPictures::Impl::report_map_sections(const ComparisonReport& report, bool flip, float error_high,
                                                      const std::vector<std::string>& map_links) {
  const Captured& c = *captured;
  // Each map on its own, linked to its EXR: FLIP (with --flip) and the error of luminance.
  for (const bool flip_maps : {true, false}) {
    if (flip_maps && !flip) continue;
    ReportSection m;
    m.id = flip_maps ? "flip" : "error";
    m.heading = flip_maps ? "FLIP maps, frame " + std::to_string(c.frame) : "Error maps, frame " + std::to_string(c.frame);
    m.text = flip_maps ? "FLIP per pixel (" + std::string(report.flip == FlipMode::Hdr ? "HDR" : "LDR") +
                             "-FLIP, magma as in the FLIP paper: 0 = no visible difference)."
                       : "Absolute error of luminance |Y_test - Y_reference| per pixel (inferno, 0 ... " +
                             format_number(error_high, 3) + ", the 99th percentile of this frame rounded up; larger "
                             "values saturate). Grey: pixels left out of the metrics (NaN or Inf).";
    for (std::size_t i = 0; i < c.tests.size(); ++i) {
      const auto& t = c.tests[i];
      if (!t.maps) continue;
      auto h = flip_maps ? heat(*t.maps, "error.flip", Colormap::Magma, 1.0f, "FLIP")
                         : heat(*t.maps, "error.Y", Colormap::Inferno, error_high, "|error| of luminance");
      if (!h) return h.error();
      const std::string file = "pictures/" + safe_name(t.name) + (flip_maps ? "-flip.png" : "-error.png");
      if (auto st = write(*h, in_report(file), "--report"); !st) return st;
      const std::string value = flip_maps ? metric_text("flip", t.metrics.value("flip")) : std::string();
      m.images.push_back({file, map_links[i], t.name + (value.empty() ? "" : ": " + value), t.name + " map",
                          flip_maps ? "flip" : "error", h->width(), h->height(), {}});
    }
    products.sections.push_back(std::move(m));
  }
  if (!c.gbuffer.empty()) {
    ReportSection g;
    g.id = "gbuffer";
    g.heading = "G-buffer, frame " + std::to_string(c.frame);
    g.text = "depth: inverse depth, near bright; normal: (N + 1) / 2 as RGB; " + c.gbuffer_note +
             "; id: a colour per material. Each links to the G-buffer EXR.";
    for (const auto& [what, p] : c.gbuffer) {
      const std::string file = "pictures/gbuffer-" + what + ".png";
      if (auto st = write(p, in_report(file), "--report"); !st) return st;
      g.images.push_back({file, rel(c.gbuffer_path), what, "G-buffer " + what, "gbuffer", p.width(), p.height(), {}});
    }
    products.sections.push_back(std::move(g));
  }
  return {};
}

Status ComparisonPictures::Impl::finish_profiles(const ComparisonReport& report) {
  if (profiles.empty() || profiles[0].frames() == 0) return {};
  const bool row = o.profile.axis == ProfileAxis::Row;
  const std::string line = o.profile.describe(width, height);
  const std::string tag = (row ? "row-" : "column-") + std::to_string(*o.profile.resolve(width, height));
  // Few frames make a thin picture: repeat each frame's line up to 8 times so that about 128 lines show.
  const int frames = int(profiles[0].frames());
  const int repeat = std::clamp(128 / std::max(1, frames), 1, 8);
  // Short lines (small images) are zoomed, pixels kept sharp, to at least 256 pixels.
  const int length = row ? width : height;
  const int zoom = std::clamp((256 + length - 1) / std::max(1, length), 1, 4);
  SheetRow cells;
  for (std::size_t i = 0; i < profiles.size(); ++i) {
    const Image img = profiles[i].image();
    std::vector<std::string> channels = profile_channels;
    auto pic = encoder->encode(img, channels);
    if (!pic) return pic.error();
    Picture shown = (row ? pic->resized(pic->width(), pic->height() * repeat) : pic->resized(pic->width() * repeat, pic->height()))
                        .zoomed(zoom);
    std::string link;
    if (report_on) {
      const std::string rel_path = "profiles/" + safe_name(names[i]) + "-" + tag + ".exr";
      Image exr = img;
      exr.metadata().extra["profileOf"] = first_paths[i];
      exr.metadata().extra["profileLine"] = line;
      if (auto st = write_exr_file(exr, in_report(rel_path), "--report"); !st) return st;
      link = rel_path;
    }
    cells.cells.push_back(SheetCell{std::move(shown), {names[i]}, link, names[i] + ": profile EXR", {}});
  }
  const std::string title = (o.title.empty() ? std::string() : o.title + ": ") + "temporal profile of " + line +
                            (row ? " (x to the right, time down: frames " : " (time to the right, y down: frames ") +
                            std::to_string(first_frame) + "-" + std::to_string(last_frame) + ")";
  auto sheet = compose_sheet(title, {cells}, *font);
  if (!sheet) return sheet.error();
  if (png_on)
    if (auto st = write(sheet->picture, (fs::path(o.png_dir) / ("profile-" + tag + ext)).string(), "--png"); !st) return st;
  if (!report_on) return {};
  const std::string file = "pictures/profile-" + tag + ".png";
  if (auto st = write(sheet->picture, in_report(file), "--report"); !st) return st;
  ReportSection s;
  s.id = "profiles";
  s.heading = "Temporal profiles (" + line + ")";
  s.text = std::string("The same ") + (row ? "row" : "column") + " of every frame stacked over time" +
           (repeat * zoom > 1 ? " (each frame " + std::to_string(repeat * zoom) + " pixels " + (row ? "tall" : "wide") +
                                    (zoom > 1 ? ", each pixel " + std::to_string(zoom) + (row ? " wide" : " tall") : std::string()) + ")"
                              : std::string()) +
           ": flicker shows as noise across time, ghosting as trails behind moving edges. --profile picks the line.";
  s.images.push_back({file, {}, "Temporal profiles of " + line + ".", "temporal profiles", "profile", sheet->picture.width(),
                      sheet->picture.height(), sheet->areas});
  products.sections.push_back(std::move(s));
  return {};
}

}  // namespace temporal
