// Forward declarations of the library's main types, for headers that only pass them around.
#pragma once

namespace temporal {
class Image;
class ImageView;
struct FrameMetadata;
struct Error;
class Status;
template <typename T> class Expected;
class SequencePattern;
struct FrameRange;
class ColorConfig;
}  // namespace temporal
