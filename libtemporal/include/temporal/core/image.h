// Planar multi-channel images.
//
// An Image is a width x height raster with any number of named channels. Every channel is its own
// contiguous plane (row-major, no padding, 64-byte aligned), so per-pixel loops over one channel are
// unit-stride and vectorise. Channels are float32 except integer data such as the material `id`, which is
// stored exactly as uint32 (a float would round ids above 2^24).
//
// Channel names follow OpenEXR: `layer.channel` (`N.X`, `motion.Y`, `depth.Z`) or bare `R,G,B,A` for the
// colour layer; docs/conventions.md lists every name the tools use.
#pragma once

#include "temporal/core/error.h"
#include "temporal/core/metadata.h"

#include <cstddef>
#include <cstdint>
#include <memory>
#include <span>
#include <string>
#include <string_view>
#include <vector>

namespace temporal {

// Memory for pixel planes: 64-byte aligned; a plane of 4 MiB or more (a 1280x1024 float plane is 5 MiB) lies in a
// block aligned to 2 MiB, rounded up to whole 2 MiB pages and advised for transparent huge pages (madvise
// MADV_HUGEPAGE) before its first touch. Planes of 64 KiB or more start at staggered offsets into their blocks, so
// that planes read side by side do not all map to the same cache sets (image.cpp). On a system whose THP mode is
// `madvise` (this build VM's) planes otherwise live on 4 KiB pages: a row loop over twenty planes then needs a TLB
// entry per 4 KiB of each. Every plane the suite
// allocates (Image's channels, the methods' state through PlaneVector, the benchmarks' streaming bounds) gets the
// same pages, so that no method is timed on better memory than its baseline or its bound (issue 27).
// allocate_plane_memory throws std::bad_alloc when the memory is not there; free_plane_memory releases it.
void* allocate_plane_memory(std::size_t bytes);
void free_plane_memory(void* p) noexcept;

// std::vector's allocator for planes kept between frames (history, weights): allocate_plane_memory.
template <typename T>
struct PlaneAllocator {
  using value_type = T;
  PlaneAllocator() = default;
  template <typename U>
  PlaneAllocator(const PlaneAllocator<U>&) noexcept {}
  T* allocate(std::size_t n) { return static_cast<T*>(allocate_plane_memory(n * sizeof(T))); }
  void deallocate(T* p, std::size_t) noexcept { free_plane_memory(p); }
  friend bool operator==(const PlaneAllocator&, const PlaneAllocator&) { return true; }
};
template <typename T>
using PlaneVector = std::vector<T, PlaneAllocator<T>>;

enum class ChannelType { Float, UInt };

// A rectangle of pixels: [x, x + width) x [y, y + height).
struct Rect {
  int x = 0, y = 0, width = 0, height = 0;
};

// A non-owning view of one float plane, possibly a crop: element (x, y) is data[y * row_stride + x].
template <typename T>
struct PlaneView {
  T* data = nullptr;
  int width = 0;
  int height = 0;
  std::ptrdiff_t row_stride = 0;  // in elements

  T& operator()(int x, int y) const { return data[y * row_stride + x]; }
  T* row(int y) const { return data + y * row_stride; }
  explicit operator bool() const { return data != nullptr; }
  PlaneView crop(const Rect& r) const { return {data + r.y * row_stride + r.x, r.width, r.height, row_stride}; }
};

class Image {
 public:
  Image() = default;
  Image(int width, int height);
  Image(const Image& other);
  Image& operator=(const Image& other);
  Image(Image&&) noexcept = default;
  Image& operator=(Image&&) noexcept = default;
  ~Image() = default;

  int width() const { return width_; }
  int height() const { return height_; }
  std::size_t pixel_count() const { return std::size_t(width_) * std::size_t(height_); }
  bool empty() const { return pixel_count() == 0; }

  // Adds a channel filled with `fill` and returns its plane. Adding an existing name returns the existing
  // plane unchanged (and nullptr if it exists with the other type).
  float* add_channel(std::string_view name, float fill = 0.0f);
  std::uint32_t* add_uint_channel(std::string_view name, std::uint32_t fill = 0);
  void remove_channel(std::string_view name);

  bool has_channel(std::string_view name) const { return find(name) >= 0; }
  ChannelType channel_type(std::string_view name) const;
  // Plane of a float channel; nullptr when absent or not float.
  float* plane(std::string_view name);
  const float* plane(std::string_view name) const;
  // Plane of a uint channel; nullptr when absent or not uint.
  std::uint32_t* uint_plane(std::string_view name);
  const std::uint32_t* uint_plane(std::string_view name) const;
  // Views (whole image) of a channel, for code that also works on crops.
  PlaneView<float> view(std::string_view name);
  PlaneView<const float> view(std::string_view name) const;

  std::size_t channel_count() const { return channels_.size(); }
  const std::string& channel_name(std::size_t i) const { return channels_[i].name; }
  std::vector<std::string> channel_names() const;
  // The channels of one layer (docs/conventions.md, "Layers"): `layer.*` in channel order (R, G, B, A, X, Y, Z,
  // then by name), or the bare colour channels R, G, B for `rgb` or empty (R, G, B, A for `rgba`) that the image
  // has. Any channel type. select_layers is the --layer rule built on it.
  std::vector<std::string> layer_channels(std::string_view layer) const;

  // A copy of a sub-rectangle with every channel.
  Image crop(const Rect& r) const;

  // Interleaved <-> planar conversion for the named channels (in that order). `interleaved` holds
  // pixel_count() * names.size() values. Missing or non-float channels are an error.
  Status to_interleaved(std::span<const std::string> names, std::span<float> interleaved) const;
  Status from_interleaved(std::span<const std::string> names, std::span<const float> interleaved);

  FrameMetadata& metadata() { return metadata_; }
  const FrameMetadata& metadata() const { return metadata_; }

 private:
  struct Channel {
    std::string name;
    ChannelType type = ChannelType::Float;
    std::shared_ptr<void> storage;  // 64-byte aligned, pixel_count() elements of 4 bytes
  };
  int find(std::string_view name) const;
  void* add(std::string_view name, ChannelType type);

  int width_ = 0;
  int height_ = 0;
  std::vector<Channel> channels_;
  FrameMetadata metadata_;
};

// The --layer rule of every tool (docs/conventions.md, "Layers"). `selection` is a layer or a comma-separated list
// of them; empty means `rgb`. Each item selects, in this order of precedence:
//   rgb       the bare colour channels R, G, B (all three); `rgba` adds A
//   NAME      the channels NAME.* (albedo -> albedo.R, albedo.G, albedo.B), in channel order (Image::layer_channels)
//   CHANNEL   else the channel with exactly that name (ssao, debug.mask)
// The result is the items' channels in the order of the items. Every selected channel must be float. Errors:
// Input, naming `file`, the item and the layers the image has (layer_names); Usage for an empty item ("a,,b") or a
// channel selected twice.
Expected<std::vector<std::string>> select_layers(const Image& image, std::string_view selection,
                                                 const std::string& file);
// The items of a selection (`rgb` for an empty one), e.g. the layers to read (ExrSelection).
std::vector<std::string> layer_items(std::string_view selection);
// What --layer can name in an image: `rgb` when it has R, G and B, then every NAME of NAME.* channels and every
// other bare channel, in channel order, each once.
std::vector<std::string> layer_names(const Image& image);
std::vector<std::string> layer_names(const std::vector<std::string>& channels);  // the same from channel names

// Counts the non-finite values (NaN, +-Inf) of a float plane.
std::size_t count_non_finite(std::span<const float> plane);

// The largest colour magnitude a method takes as a sample (docs/conventions.md, "Non-finite values"). A larger one
// is treated as NaN is: no sample at that pixel this frame. Finite is not enough (issue 26 item 12: FLT_MAX in one
// frame made phlm's later frames NaN). Seed 003's method squares and cubes its inputs in float: the a-priori error
// of eq. 5 is squared (||e||^2) and the neighbourhood box's variance sums squares (both overflow past ~1.8e19), and
// the feature's phi(v, l) = a l^2 + b v l^3 (section 5.1) overflows past l ~ 1.1e11 at the largest motion the
// reprojection accepts (1e6 px, temporal/core/reproject.h) and b = 0.25. 1e10 keeps every one of them finite, and is
// far above any scene-linear radiance a renderer writes (the sun's disc is ~1.6e9 cd/m^2).
inline constexpr float kMaxSampleMagnitude = 1e10f;
// True for a value a method takes as a sample: finite and at most kMaxSampleMagnitude in magnitude (false for NaN).
inline bool usable_sample(float v) { return v >= -kMaxSampleMagnitude && v <= kMaxSampleMagnitude; }

}  // namespace temporal
