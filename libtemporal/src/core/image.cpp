#include "temporal/core/image.h"

#include <cmath>
#include <cstdlib>
#include <cstring>
#include <new>

namespace temporal {
namespace {

// 64-byte aligned planes: full cache lines and aligned vector loads at the start of every plane.
std::shared_ptr<void> allocate_plane(std::size_t count) {
  const std::size_t bytes = ((count * 4 + 63) / 64) * 64;
  void* p = std::aligned_alloc(64, bytes == 0 ? 64 : bytes);
  if (!p) throw std::bad_alloc();
  return std::shared_ptr<void>(p, [](void* q) { std::free(q); });
}

}  // namespace

Image::Image(int width, int height) : width_(width < 0 ? 0 : width), height_(height < 0 ? 0 : height) {}

Image::Image(const Image& other) : width_(other.width_), height_(other.height_), metadata_(other.metadata_) {
  channels_.reserve(other.channels_.size());
  for (const auto& c : other.channels_) {
    Channel copy{c.name, c.type, allocate_plane(pixel_count())};
    std::memcpy(copy.storage.get(), c.storage.get(), pixel_count() * 4);
    channels_.push_back(std::move(copy));
  }
}

Image& Image::operator=(const Image& other) {
  if (this != &other) {
    Image copy(other);
    *this = std::move(copy);
  }
  return *this;
}

int Image::find(std::string_view name) const {
  for (std::size_t i = 0; i < channels_.size(); ++i)
    if (channels_[i].name == name) return int(i);
  return -1;
}

void* Image::add(std::string_view name, ChannelType type) {
  if (const int i = find(name); i >= 0) return channels_[i].type == type ? channels_[i].storage.get() : nullptr;
  channels_.push_back(Channel{std::string(name), type, allocate_plane(pixel_count())});
  return channels_.back().storage.get();
}

float* Image::add_channel(std::string_view name, float fill) {
  const bool existed = has_channel(name);
  auto* p = static_cast<float*>(add(name, ChannelType::Float));
  if (p && !existed) std::fill(p, p + pixel_count(), fill);
  return p;
}

std::uint32_t* Image::add_uint_channel(std::string_view name, std::uint32_t fill) {
  const bool existed = has_channel(name);
  auto* p = static_cast<std::uint32_t*>(add(name, ChannelType::UInt));
  if (p && !existed) std::fill(p, p + pixel_count(), fill);
  return p;
}

void Image::remove_channel(std::string_view name) {
  if (const int i = find(name); i >= 0) channels_.erase(channels_.begin() + i);
}

ChannelType Image::channel_type(std::string_view name) const {
  const int i = find(name);
  return i >= 0 ? channels_[i].type : ChannelType::Float;
}

float* Image::plane(std::string_view name) {
  const int i = find(name);
  return i >= 0 && channels_[i].type == ChannelType::Float ? static_cast<float*>(channels_[i].storage.get()) : nullptr;
}
const float* Image::plane(std::string_view name) const { return const_cast<Image*>(this)->plane(name); }

std::uint32_t* Image::uint_plane(std::string_view name) {
  const int i = find(name);
  return i >= 0 && channels_[i].type == ChannelType::UInt ? static_cast<std::uint32_t*>(channels_[i].storage.get())
                                                          : nullptr;
}
const std::uint32_t* Image::uint_plane(std::string_view name) const { return const_cast<Image*>(this)->uint_plane(name); }

PlaneView<float> Image::view(std::string_view name) { return {plane(name), width_, height_, width_}; }
PlaneView<const float> Image::view(std::string_view name) const { return {plane(name), width_, height_, width_}; }

std::vector<std::string> Image::channel_names() const {
  std::vector<std::string> names;
  names.reserve(channels_.size());
  for (const auto& c : channels_) names.push_back(c.name);
  return names;
}

std::vector<std::string> Image::layer_channels(std::string_view layer) const {
  std::vector<std::string> names;
  for (const auto& c : channels_) {
    const auto dot = c.name.rfind('.');
    if (layer.empty() || layer == "rgb" || layer == "rgba") {
      if (dot == std::string::npos) names.push_back(c.name);
    } else if (dot != std::string::npos && std::string_view(c.name).substr(0, dot) == layer) {
      names.push_back(c.name);
    }
  }
  return names;
}

Image Image::crop(const Rect& r) const {
  Image out(r.width, r.height);
  out.metadata_ = metadata_;
  const int x0 = std::max(0, r.x), y0 = std::max(0, r.y);
  const int x1 = std::min(width_, r.x + r.width), y1 = std::min(height_, r.y + r.height);
  for (const auto& c : channels_) {
    void* dst = out.add(c.name, c.type);
    std::memset(dst, 0, out.pixel_count() * 4);
    for (int y = y0; y < y1; ++y) {
      const auto* src_row = static_cast<const std::byte*>(c.storage.get()) + (std::size_t(y) * width_ + x0) * 4;
      auto* dst_row = static_cast<std::byte*>(dst) + (std::size_t(y - r.y) * r.width + (x0 - r.x)) * 4;
      if (x1 > x0) std::memcpy(dst_row, src_row, std::size_t(x1 - x0) * 4);
    }
  }
  return out;
}

Status Image::to_interleaved(std::span<const std::string> names, std::span<float> interleaved) const {
  const std::size_t n = names.size(), count = pixel_count();
  if (interleaved.size() < n * count) return Error::internal("to_interleaved: destination too small");
  for (std::size_t c = 0; c < n; ++c) {
    const float* src = plane(names[c]);
    if (!src) return Error::internal("to_interleaved: no float channel '" + names[c] + "'");
    float* dst = interleaved.data() + c;
    for (std::size_t i = 0; i < count; ++i) dst[i * n] = src[i];
  }
  return {};
}

Status Image::from_interleaved(std::span<const std::string> names, std::span<const float> interleaved) {
  const std::size_t n = names.size(), count = pixel_count();
  if (interleaved.size() < n * count) return Error::internal("from_interleaved: source too small");
  for (std::size_t c = 0; c < n; ++c) {
    float* dst = add_channel(names[c]);
    if (!dst) return Error::internal("from_interleaved: channel '" + names[c] + "' is not float");
    const float* src = interleaved.data() + c;
    for (std::size_t i = 0; i < count; ++i) dst[i] = src[i * n];
  }
  return {};
}

std::size_t count_non_finite(std::span<const float> plane) {
  std::size_t n = 0;
  for (float v : plane) n += std::isfinite(v) ? 0 : 1;
  return n;
}

}  // namespace temporal
