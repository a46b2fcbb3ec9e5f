// OpenEXR input and output through OpenImageIO.
//
// Files are multi-part: one part per layer (`rgba` for R,G,B,A first, then `depth`, `N`, `motion`, `id`, ...),
// so a tool that needs only `motion` decompresses only that part (measured ~3x faster than a single part
// at 1280x1024; docs/conventions.md). Every part's header carries the FrameMetadata. Single-part files
// written by other programs are read too.
#pragma once

#include "temporal/core/error.h"
#include "temporal/core/image.h"

#include <span>
#include <string>
#include <vector>

namespace temporal {

// What to read. Each entry is an exact channel name (`motion.X`), a layer name (`motion` selects
// `motion.*`), or `rgb` / `rgba` for the bare colour channels. An empty list reads every channel.
struct ExrSelection {
  std::vector<std::string> layers;
};

enum class ExrCompression { None, Zip, Piz, Dwaa };

struct ExrWriteOptions {
  // Lossless by default. DWA is refused for anything but colour: it compresses channels named `*.Y` as
  // luminance, lossily, even when they hold data (docs/building.md).
  ExrCompression compression = ExrCompression::Zip;
  // Channels (exact names or layer names) stored as half float; all others are float32 (uint stays uint).
  std::vector<std::string> half_layers;
};

// Header-only information about a file.
struct ExrInfo {
  int width = 0;
  int height = 0;
  std::vector<std::string> channels;
  FrameMetadata metadata;
};

Expected<ExrInfo> read_exr_info(const std::string& path);

// Reads the selected channels. A selected layer that is absent is an Input error naming the layers the
// file has. A channel stored as uint (`id`) is read exactly as uint; half and float become float32.
Expected<Image> read_exr(const std::string& path, const ExrSelection& selection = {});

// The same two readers over the bytes of an EXR file held in memory; `name` names it in messages and must end in
// .exr. Every check of the file readers applies (tests/fuzz/exr_fuzz reads its inputs this way: no file per run).
Expected<ExrInfo> read_exr_info(std::span<const std::uint8_t> bytes, const std::string& name);
Expected<Image> read_exr(std::span<const std::uint8_t> bytes, const std::string& name,
                         const ExrSelection& selection = {});

// Writes atomically: a temporary file beside `path` is written and then renamed over it, so an
// interrupted run never leaves a truncated EXR. Creates missing parent folders.
// The R, G, B channels of `path` (read_exr with the selection {"rgb"}): the reader handed to stages that read
// one extra image per frame without linking this stage (MorphStageIO::read_rgb).
Expected<Image> read_exr_rgb(const std::string& path);

Status write_exr(const std::string& path, const Image& image, const ExrWriteOptions& options = {});

// Parses `none|zip|piz|dwaa`.
Expected<ExrCompression> parse_compression(const std::string& name);

}  // namespace temporal
