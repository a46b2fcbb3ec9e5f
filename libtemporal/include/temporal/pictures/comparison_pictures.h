// The pictures of a comparison, made while compare streams the frames (ComparisonHooks::frame, so nothing is
// read twice): display-encoded frames, FLIP and error heat maps, G-buffer pictures, the contact sheet of one
// frame with zoomed crops, temporal profiles, and the side-by-side video. `compare --png DIR` and
// `compare --report DIR` (docs/compare.md, "Pictures") are this class; temporal/report/ adds the charts and the
// page.
#pragma once

#include "temporal/core/error.h"
#include "temporal/io/runner.h"
#include "temporal/compare/comparison.h"
#include "temporal/pictures/display.h"
#include "temporal/pictures/html.h"
#include "temporal/pictures/profile.h"

#include <memory>
#include <optional>
#include <string>
#include <vector>

namespace temporal {

struct PictureOptions {
  // --png DIR: for every frame, DIR/<name>.NNNN.<ext> of the reference (name "reference") and each test,
  // DIR/<name>-flip.NNNN (with FLIP) and DIR/<name>-error.NNNN heat maps with their colour bars, and with a
  // G-buffer DIR/gbuffer-{depth,normal,motion,id}.NNNN; then DIR/sheet.NNNN and DIR/profile-<line>.<ext>.
  std::string png_dir;
  std::string png_format = "png";  // png | jpg
  // --report DIR: the pictures of the report page under DIR/pictures (contact sheet, maps, G-buffer, profiles),
  // the EXRs they link to under DIR/maps and DIR/profiles, and DIR/video.mp4.
  std::string report_dir;
  bool video = true;               // the report's video (needs ffmpeg)
  std::string title;               // on the contact sheet
  DisplayOptions display;
  std::vector<Rect> crops;         // zoomed regions; empty: picked where FLIP (or the error) is largest
  int picked_crops = 2;            // how many to pick
  std::optional<int> sheet_frame;  // the contact sheet's frame; empty: the last compared frame
  ProfileLine profile;             // the line of the temporal profiles (default: the middle row)
  int max_tile_width = 480;        // the sheet shrinks wider frames to this
};

// What finish() made for the report page (paths relative to the report folder), and the outputs that failed
// without stopping the rest (a missing ffmpeg loses the video, not the page).
struct PictureProducts {
  std::vector<ReportSection> sections;
  std::string video, video_poster, video_caption;
  int video_width = 0, video_height = 0;
  std::vector<Error> errors;
  std::vector<std::string> written;  // every file written, for --verbose
};

class ComparisonPictures {
 public:
  // Checks the options (formats, crops, the display space) before anything runs. `inputs`: the files of the
  // comparison, which no picture, map or video may replace (it must outlive this object; may be null).
  static Expected<std::unique_ptr<ComparisonPictures>> create(const PictureOptions& options,
                                                              const ComparisonSetup& setup,
                                                              const ProtectedInputs* inputs);
  ~ComparisonPictures();

  // Sets the hooks' frame observer (and asks for the error maps and the G-buffer's N, depth and id). This object
  // must outlive the comparison run with these hooks.
  void attach(ComparisonHooks& hooks);
  // After the comparison: the contact sheet, the maps of its frame, the profiles, the end of the video.
  Expected<PictureProducts> finish(const ComparisonReport& report);

 private:
  struct Impl;
  explicit ComparisonPictures(std::unique_ptr<Impl> impl);
  std::unique_ptr<Impl> impl_;
};

// The short label of a metric on pictures ("PSNR", "SSIM", "FLIP", ...: its registry entry's label and unit,
// temporal/compare/comparison.h), and a frame's value as text with it: "PSNR 31.20 dB".
std::string metric_label(std::string_view metric);
std::string metric_text(std::string_view metric, double value);

}  // namespace temporal
