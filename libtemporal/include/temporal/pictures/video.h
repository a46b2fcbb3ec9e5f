// H.264 video of pictures, encoded by Debian's `ffmpeg` command-line tool (libx264): frames are streamed to it as
// raw RGB through a socket (nothing is written per frame), yuv420p for players and browsers, at the sequence's
// frame rate (120 Hz sequences stay 120 Hz). The file is written atomically (temporary file, renamed when ffmpeg
// succeeds; removed on SIGINT or failure).
#pragma once

#include "temporal/core/error.h"
#include "temporal/pictures/picture.h"

#include <memory>
#include <string>

namespace temporal {

struct VideoOptions {
  double fps = 30.0;      // frames per second of the file
  int crf = 18;           // x264 constant rate factor: 18 is visually lossless for most content
  std::string ffmpeg;     // the program; empty: `ffmpeg` from PATH
};

class VideoWriter {
 public:
  // Starts ffmpeg for a width x height video (both even, >= 2). Errors: Usage for bad sizes or fps, Output when
  // ffmpeg is not installed (with how to install it) or cannot start.
  static Expected<VideoWriter> open(const std::string& path, int width, int height, const VideoOptions& options);

  VideoWriter(VideoWriter&&) noexcept;
  VideoWriter& operator=(VideoWriter&&) noexcept;
  ~VideoWriter();  // stops ffmpeg and removes the temporary file unless finished

  // Sends one frame (the size given to open). Output error when ffmpeg stopped (its message included).
  Status add(const Picture& frame);
  // Ends the stream, waits for ffmpeg and moves the file into place. Output error with ffmpeg's message when it
  // failed or no frame was sent.
  Status finish();
  std::size_t frames() const;

 private:
  struct Impl;
  explicit VideoWriter(std::unique_ptr<Impl> impl);
  std::unique_ptr<Impl> impl_;
};

// The ffmpeg program in PATH, or empty.
std::string find_ffmpeg();

}  // namespace temporal
