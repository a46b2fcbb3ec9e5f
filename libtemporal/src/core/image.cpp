#include "temporal/core/image.h"

#include <algorithm>
#include <atomic>
#include <cmath>
#include <cstdint>
#include <cstdlib>
#include <cstring>
#include <new>

#if defined(__linux__)
#include <sys/mman.h>
#endif

namespace temporal {

// Planes of 64 KiB or more start at a staggered offset into their block, from a counter: (33 n mod 64) cache lines
// (a different set of a 4 KiB-periodic L1 for each of 64 successive planes) plus, for planes of 4 MiB or more,
// (7 n mod 16) x 4 KiB (spread over the 64 KiB period of a 512 KiB 8-way L2); the base pointer is kept in the 8
// bytes before the plane, for free_plane_memory. Without it every large plane began on a 2 MiB boundary (and
// mid-sized ones, from glibc's page-aligned mmap'd blocks, likely at one offset into a 4 KiB page), so the planes a
// row loop reads side by side at the same pixel (the history fetch: the previous frame's channels, depth and ids,
// this frame's motion, depth and ids) had the same low address bits and fell on the same sets of the L1 and L2
// caches: more streams than their 8 ways. Issue 27, 2026-11-29: herzog's history fetch (fused_aligned_run) took
// 13-18 % less time with its previous planes read at staggered offsets (a probe); docs/history/upsample-st-speed.md,
// "sixth session".
namespace {
std::atomic<std::size_t> stagger_counter{0};
}  // namespace

void* allocate_plane_memory(std::size_t bytes) {
  constexpr std::size_t kHuge = std::size_t(2) << 20;
  bytes = std::max<std::size_t>(64, (bytes + 63) / 64 * 64);
  const bool huge = bytes >= 2 * kHuge;
  std::size_t offset = 64;  // room for the base pointer
  if (bytes >= (std::size_t(64) << 10)) {
    const std::size_t n = stagger_counter.fetch_add(1, std::memory_order_relaxed);
    offset += (n * 33 % 64) * 64;
    if (huge) offset += (n * 7 % 16) * 4096;
  }
  std::size_t total = bytes + offset;
  if (huge) total = (total + kHuge - 1) / kHuge * kHuge;
  void* base = std::aligned_alloc(huge ? kHuge : 64, total);
  if (!base) throw std::bad_alloc();
#if defined(__linux__) && defined(MADV_HUGEPAGE)
  if (huge) (void)madvise(base, total, MADV_HUGEPAGE);  // advice only: a refusal leaves 4 KiB pages
#endif
  char* plane = static_cast<char*>(base) + offset;
  std::memcpy(plane - sizeof(void*), &base, sizeof(void*));
  return plane;
}

void free_plane_memory(void* p) noexcept {
  if (!p) return;
  void* base;
  std::memcpy(&base, static_cast<char*>(p) - sizeof(void*), sizeof(void*));
  std::free(base);
}

namespace {

std::shared_ptr<void> allocate_plane(std::size_t count) {
  return std::shared_ptr<void>(allocate_plane_memory(count * 4), [](void* q) { free_plane_memory(q); });
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

namespace {
// Order of the usual channel suffixes; others follow by name. Files and tools agree on it (OpenImageIO reads
// R, G, B, A first), and a test and its reference pair their channels by it.
int suffix_rank(std::string_view suffix) {
  static constexpr std::string_view kOrder[] = {"R", "G", "B", "A", "X", "Y", "Z"};
  for (int i = 0; i < 7; ++i)
    if (suffix == kOrder[i]) return i;
  return 7;
}
std::string_view suffix_of(std::string_view name) {
  const auto dot = name.rfind('.');
  return dot == std::string_view::npos ? name : name.substr(dot + 1);
}
}  // namespace

std::vector<std::string> Image::layer_channels(std::string_view layer) const {
  std::vector<std::string> names;
  if (layer.empty() || layer == "rgb" || layer == "rgba") {
    for (const char* c : {"R", "G", "B", "A"})
      if ((layer == "rgba" || c[0] != 'A') && has_channel(c)) names.emplace_back(c);
    return names;
  }
  for (const auto& c : channels_) {
    const auto dot = c.name.rfind('.');
    if (dot != std::string::npos && std::string_view(c.name).substr(0, dot) == layer) names.push_back(c.name);
  }
  std::stable_sort(names.begin(), names.end(), [](const std::string& a, const std::string& b) {
    const int ra = suffix_rank(suffix_of(a)), rb = suffix_rank(suffix_of(b));
    return ra != rb ? ra < rb : a < b;
  });
  return names;
}

std::vector<std::string> layer_items(std::string_view selection) {
  std::vector<std::string> items;
  std::size_t begin = 0;
  while (true) {
    const auto comma = selection.find(',', begin);
    items.emplace_back(selection.substr(begin, comma == std::string_view::npos ? std::string_view::npos : comma - begin));
    if (comma == std::string_view::npos) break;
    begin = comma + 1;
  }
  if (items.size() == 1 && items.front().empty()) items.front() = "rgb";
  return items;
}

std::vector<std::string> layer_names(const Image& image) { return layer_names(image.channel_names()); }

std::vector<std::string> layer_names(const std::vector<std::string>& channels) {
  std::vector<std::string> names;
  auto add = [&](std::string n) {
    if (std::find(names.begin(), names.end(), n) == names.end()) names.push_back(std::move(n));
  };
  auto has = [&](const char* c) { return std::find(channels.begin(), channels.end(), c) != channels.end(); };
  if (has("R") && has("G") && has("B")) add("rgb");
  for (const std::string& c : channels) {
    const auto dot = c.rfind('.');
    if (dot != std::string::npos) add(c.substr(0, dot));
    else if (c != "R" && c != "G" && c != "B" && c != "A") add(c);
  }
  return names;
}

Expected<std::vector<std::string>> select_layers(const Image& image, std::string_view selection,
                                                 const std::string& file) {
  auto have = [&] {
    std::string text;
    for (const auto& n : layer_names(image)) text += (text.empty() ? "" : ", ") + n;
    return text.empty() ? std::string("none") : text;
  };
  std::vector<std::string> out;
  for (const std::string& item : layer_items(selection)) {
    if (item.empty()) return Error::usage("--layer '" + std::string(selection) + "' has an empty item");
    std::vector<std::string> names = image.layer_channels(item);
    const bool colour = item == "rgb" || item == "rgba";
    if (colour && names.size() != (item == "rgb" ? 3u : 4u))
      return Error::input(file, "no layer '" + item + "': " + item + " needs the bare channels " +
                                    (item == "rgb" ? "R, G, B" : "R, G, B, A") + " (have: " + have() +
                                    "); pick another with --layer");
    if (names.empty() && image.has_channel(item)) names.push_back(item);
    if (names.empty())
      return Error::input(file, "no layer '" + item + "' (have: " + have() + "); pick another with --layer");
    for (auto& n : names) {
      if (image.channel_type(n) != ChannelType::Float)
        return Error::input(file, "channel '" + n + "' of layer '" + item + "' is not float (uint data such as the "
                                  "material id cannot be selected with --layer)");
      if (std::find(out.begin(), out.end(), n) != out.end())
        return Error::usage("--layer '" + std::string(selection) + "' selects channel '" + n + "' twice");
      out.push_back(std::move(n));
    }
  }
  return out;
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
  // A 32-bit count per block of 2^20 values: the loop vectorises without widening every lane to 64 bits (it was 4
  // floats and two 64-bit adds per step at x86-64-v2, in the serial start of every upsample-st frame).
  std::size_t total = 0;
  for (std::size_t b = 0; b < plane.size(); b += std::size_t(1) << 20) {
    const std::size_t e = std::min(plane.size(), b + (std::size_t(1) << 20));
    std::uint32_t n = 0;
    for (std::size_t i = b; i < e; ++i) n += std::isfinite(plane[i]) ? 0u : 1u;
    total += n;
  }
  return total;
}

}  // namespace temporal
