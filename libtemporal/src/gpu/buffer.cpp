#include "temporal/gpu/buffer.h"

#include <utility>
#include <vector>

namespace temporal::gpu {

Status ImageBuffer::create_cleared(std::shared_ptr<Context> context, int width, int height, int planes,
                                   ImageBuffer& buffer) {
  auto created = create(std::move(context), width, height, planes);
  if (!created) return created.error();
  buffer = std::move(*created);
  return buffer.clear(0, planes);
}

namespace {
// create_all's and create_all_cleared's work: every buffer made (and cleared) before any is replaced.
Status create_each(const std::shared_ptr<Context>& context, std::initializer_list<ImageBuffer::Shape> shapes,
                   bool cleared) {
  std::vector<ImageBuffer> made;
  made.reserve(shapes.size());
  for (const ImageBuffer::Shape& shape : shapes) {
    auto created = ImageBuffer::create(context, shape.width, shape.height, shape.planes);
    if (!created) return created.error();
    if (cleared)
      if (Status s = created->clear(0, shape.planes); !s) return s;
    made.push_back(std::move(*created));
  }
  auto next = made.begin();
  for (const ImageBuffer::Shape& shape : shapes) *shape.buffer = std::move(*next++);
  return Status::ok();
}
}  // namespace

Status ImageBuffer::create_all(const std::shared_ptr<Context>& context, std::initializer_list<Shape> shapes) {
  return create_each(context, shapes, false);
}

Status ImageBuffer::create_all_cleared(const std::shared_ptr<Context>& context, std::initializer_list<Shape> shapes) {
  return create_each(context, shapes, true);
}

Expected<ImageBuffer> ImageBuffer::create(std::shared_ptr<Context> context, int width, int height, int planes) {
  if (!context) return Error::internal("gpu::ImageBuffer: no context");
  if (width <= 0 || height <= 0 || planes <= 0) return Error::internal("gpu::ImageBuffer: empty size");
  if (Status s = context->make_current(); !s) return s.error();
  const double bytes = double(width) * double(height) * double(planes) * 4.0;
  if (bytes > double(context->max_storage_bytes()))
    return Error::usage("--device gpu: a " + std::to_string(width) + "x" + std::to_string(height) + " buffer of " +
                        std::to_string(planes) + " planes (" + std::to_string(static_cast<long long>(bytes)) +
                        " bytes) exceeds the device's storage block size (" +
                        std::to_string(context->max_storage_bytes()) + " bytes)");
  const GlFunctions& gl = context->gl();
  ImageBuffer b;
  b.context_ = std::move(context);
  b.width_ = width;
  b.height_ = height;
  b.planes_ = planes;
  gl.GenBuffers(1, &b.buffer_);
  gl.BindBuffer(GL_SHADER_STORAGE_BUFFER, b.buffer_);
  gl.BufferData(GL_SHADER_STORAGE_BUFFER, GLsizeiptr(b.bytes()), nullptr, GL_DYNAMIC_COPY);
  if (Status s = b.context_->check("allocating an image buffer"); !s) return s.error();
  return b;
}

ImageBuffer::~ImageBuffer() {
  if (buffer_ && context_ && context_->make_current()) context_->gl().DeleteBuffers(1, &buffer_);
}

ImageBuffer::ImageBuffer(ImageBuffer&& other) noexcept { *this = std::move(other); }

ImageBuffer& ImageBuffer::operator=(ImageBuffer&& other) noexcept {
  if (this != &other) {
    if (buffer_ && context_ && context_->make_current()) context_->gl().DeleteBuffers(1, &buffer_);
    context_ = std::move(other.context_);
    buffer_ = std::exchange(other.buffer_, 0u);
    width_ = std::exchange(other.width_, 0);
    height_ = std::exchange(other.height_, 0);
    planes_ = std::exchange(other.planes_, 0);
  }
  return *this;
}

Status ImageBuffer::check_plane(int plane, const char* what) const {
  if (!buffer_) return Error::internal(std::string("gpu::ImageBuffer::") + what + ": empty buffer");
  if (plane < 0 || plane >= planes_)
    return Error::internal(std::string("gpu::ImageBuffer::") + what + ": plane " + std::to_string(plane) +
                           " out of range");
  return context_->make_current();
}

namespace {
Status put(const Context& ctx, unsigned buffer, std::size_t offset, std::size_t bytes, const void* data) {
  const GlFunctions& gl = ctx.gl();
  gl.BindBuffer(GL_SHADER_STORAGE_BUFFER, buffer);
  gl.BufferSubData(GL_SHADER_STORAGE_BUFFER, GLintptr(offset), GLsizeiptr(bytes), data);
  return ctx.check("uploading a plane");
}
Status get(const Context& ctx, unsigned buffer, std::size_t offset, std::size_t bytes, void* data) {
  const GlFunctions& gl = ctx.gl();
  gl.BindBuffer(GL_SHADER_STORAGE_BUFFER, buffer);
  gl.GetBufferSubData(GL_SHADER_STORAGE_BUFFER, GLintptr(offset), GLsizeiptr(bytes), data);
  return ctx.check("downloading a plane");
}
}  // namespace

Status ImageBuffer::upload(int plane, const float* data) {
  if (Status s = check_plane(plane, "upload"); !s) return s;
  return put(*context_, buffer_, std::size_t(base(plane)) * 4, pixel_count() * 4, data);
}
Status ImageBuffer::upload(int plane, const std::uint32_t* data) {
  if (Status s = check_plane(plane, "upload"); !s) return s;
  return put(*context_, buffer_, std::size_t(base(plane)) * 4, pixel_count() * 4, data);
}
Status ImageBuffer::download(int plane, float* data) const {
  if (Status s = check_plane(plane, "download"); !s) return s;
  return get(*context_, buffer_, std::size_t(base(plane)) * 4, pixel_count() * 4, data);
}
Status ImageBuffer::download(int plane, std::uint32_t* data) const {
  if (Status s = check_plane(plane, "download"); !s) return s;
  return get(*context_, buffer_, std::size_t(base(plane)) * 4, pixel_count() * 4, data);
}

Status ImageBuffer::upload(int plane, const Image& image, const std::string& name) {
  if (image.width() != width_ || image.height() != height_)
    return Error::internal("gpu::ImageBuffer::upload: image size differs from the buffer's");
  if (const float* f = image.plane(name)) return upload(plane, f);
  if (const std::uint32_t* u = image.uint_plane(name)) return upload(plane, u);
  return Error::input({}, "image has no channel '" + name + "'");
}

Status ImageBuffer::download(int plane, Image& image, const std::string& name, bool as_uint) const {
  if (image.width() != width_ || image.height() != height_)
    return Error::internal("gpu::ImageBuffer::download: image size differs from the buffer's");
  if (as_uint) {
    std::uint32_t* u = image.add_uint_channel(name);
    if (!u) return Error::internal("gpu::ImageBuffer::download: '" + name + "' exists as a float channel");
    return download(plane, u);
  }
  float* f = image.add_channel(name);
  if (!f) return Error::internal("gpu::ImageBuffer::download: '" + name + "' exists as a uint channel");
  return download(plane, f);
}

Status ImageBuffer::clear(int first, int count) {
  if (Status s = check_plane(first, "clear"); !s) return s;
  if (Status s = check_plane(first + count - 1, "clear"); !s) return s;
  const GlFunctions& gl = context_->gl();
  gl.BindBuffer(GL_SHADER_STORAGE_BUFFER, buffer_);
  const std::vector<std::uint8_t> zeros(pixel_count() * std::size_t(count) * 4, 0);
  gl.BufferSubData(GL_SHADER_STORAGE_BUFFER, GLintptr(std::size_t(base(first)) * 4), GLsizeiptr(zeros.size()),
                   zeros.data());
  return context_->check("clearing planes");
}

Status ImageBuffer::copy_plane(const ImageBuffer& source, int from, int to) {
  if (Status s = check_plane(to, "copy_plane"); !s) return s;
  if (Status s = source.check_plane(from, "copy_plane"); !s) return s;
  if (source.pixel_count() != pixel_count()) return Error::internal("gpu::ImageBuffer::copy_plane: sizes differ");
  const GlFunctions& gl = context_->gl();
  gl.BindBuffer(GL_COPY_READ_BUFFER, source.buffer_);
  gl.BindBuffer(GL_COPY_WRITE_BUFFER, buffer_);
  gl.CopyBufferSubData(GL_COPY_READ_BUFFER, GL_COPY_WRITE_BUFFER, GLintptr(std::size_t(source.base(from)) * 4),
                       GLintptr(std::size_t(base(to)) * 4), GLsizeiptr(pixel_count() * 4));
  return context_->check("copying a plane");
}

void ImageBuffer::bind(unsigned binding) const {
  if (context_ && context_->make_current()) context_->gl().BindBufferBase(GL_SHADER_STORAGE_BUFFER, binding, buffer_);
}

}  // namespace temporal::gpu
