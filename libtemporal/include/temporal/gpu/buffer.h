// Planar images on the GPU: the planes of a temporal::Image, 4 bytes per value (float, or uint32 for ids), one
// after the other in one shader storage buffer. Plane p of a width x height buffer starts at element
// p * width * height, the layout of an Image's planes, so an upload or download is one copy per plane.
// Kernels declare the buffer with gpu::glsl::storage() and address plane p of pixel i as name[base_p + i].
#pragma once

#include "temporal/core/error.h"
#include "temporal/core/image.h"
#include "temporal/gpu/context.h"

#include <cstddef>
#include <cstdint>
#include <initializer_list>
#include <memory>
#include <span>
#include <string>

namespace temporal::gpu {

class ImageBuffer {
 public:
  ImageBuffer() = default;
  // A buffer of `planes` planes of width x height values (contents undefined). Fails when the buffer exceeds the
  // device's storage block size or the driver cannot allocate it.
  static Expected<ImageBuffer> create(std::shared_ptr<Context> context, int width, int height, int planes);
  // Makes `buffer` a new buffer like create()'s with every plane 0 (a state's histories before the first frame).
  static Status create_cleared(std::shared_ptr<Context> context, int width, int height, int planes,
                               ImageBuffer& buffer);
  // One buffer of a set made together (create_all): where it goes and its size.
  struct Shape {
    ImageBuffer* buffer;
    int width, height, planes;
  };
  // Makes each shape's buffer a new buffer like create()'s, all or none: on an error no buffer changed. The buffers
  // a kernel needs for one frame size, (re)made together.
  static Status create_all(const std::shared_ptr<Context>& context, std::initializer_list<Shape> shapes);
  // The same with every plane 0 (create_cleared()): a state's buffers before its first frame.
  static Status create_all_cleared(const std::shared_ptr<Context>& context, std::initializer_list<Shape> shapes);
  ~ImageBuffer();
  ImageBuffer(ImageBuffer&& other) noexcept;
  ImageBuffer& operator=(ImageBuffer&& other) noexcept;
  ImageBuffer(const ImageBuffer&) = delete;
  ImageBuffer& operator=(const ImageBuffer&) = delete;

  int width() const { return width_; }
  int height() const { return height_; }
  int planes() const { return planes_; }
  std::size_t pixel_count() const { return std::size_t(width_) * std::size_t(height_); }
  std::size_t bytes() const { return pixel_count() * std::size_t(planes_) * 4; }
  // First element of plane p (the base a kernel adds to the pixel index).
  std::uint32_t base(int plane) const { return std::uint32_t(std::size_t(plane) * pixel_count()); }
  bool empty() const { return buffer_ == 0; }

  // Copies one plane (pixel_count() values) to or from the host.
  Status upload(int plane, const float* data);
  Status upload(int plane, const std::uint32_t* data);
  Status download(int plane, float* data) const;
  Status download(int plane, std::uint32_t* data) const;
  // Channel `name` of `image` (float or uint, same size) into plane p; an input error when it is missing.
  Status upload(int plane, const Image& image, const std::string& name);
  // Plane p into channel `name` of `image` (added as float, or as uint when `as_uint`).
  Status download(int plane, Image& image, const std::string& name, bool as_uint = false) const;
  // Sets `count` planes from `first` to zero.
  Status clear(int first, int count);
  // Copies plane `from` of `source` into plane `to` of this buffer (same size), on the device.
  Status copy_plane(const ImageBuffer& source, int from, int to);

  // Binds the whole buffer to shader storage binding `binding`.
  void bind(unsigned binding) const;
  unsigned handle() const { return buffer_; }

 private:
  Status check_plane(int plane, const char* what) const;
  std::shared_ptr<Context> context_;
  unsigned buffer_ = 0;
  int width_ = 0, height_ = 0, planes_ = 0;
};

}  // namespace temporal::gpu
