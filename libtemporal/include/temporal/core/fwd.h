// Forward declarations of the library's common types, for headers that only pass them around.
#pragma once

namespace temporal {
class Image;
struct FrameMetadata;
struct Error;
class Status;
template <typename T>
class Expected;
class SequencePattern;
struct FrameRange;
class ColorConfig;
struct Param;
class FrameStage;
}  // namespace temporal
