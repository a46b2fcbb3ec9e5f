// OpenEXR I/O through OpenImageIO: multi-part files (one part per layer), planar images, atomic writes.
#include "temporal/io/exr.h"

#include "temporal/io/atomic_file.h"

#include <OpenEXR/openexr.h>
#include <OpenImageIO/filesystem.h>
#include <OpenImageIO/imageio.h>

#include <glm/gtc/type_ptr.hpp>

#include <unistd.h>

#include <algorithm>
#include <cmath>
#include <numeric>
#include <cctype>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <map>
#include <set>
#include <span>

namespace temporal {
namespace {

namespace fs = std::filesystem;
using OIIO::ImageInput;
using OIIO::ImageOutput;
using OIIO::ImageSpec;
using OIIO::TypeDesc;

constexpr const char* kColourPart = "rgba";

// Layer of a channel: the text before the last '.', or "" for bare channels (R, G, B, A, Z, id).
std::string layer_of(const std::string& channel) {
  const auto dot = channel.rfind('.');
  return dot == std::string::npos ? std::string() : channel.substr(0, dot);
}

bool is_colour_channel(const std::string& c) { return c == "R" || c == "G" || c == "B" || c == "A"; }

bool selected(const ExrSelection& selection, const std::string& channel) {
  if (selection.layers.empty()) return true;
  const std::string layer = layer_of(channel);
  for (const auto& s : selection.layers) {
    if (s == channel) return true;
    if (!layer.empty() && s == layer) return true;
    if ((s == "rgb" && (channel == "R" || channel == "G" || channel == "B")) || (s == "rgba" && is_colour_channel(channel)))
      return true;
  }
  return false;
}

// True when a selection entry matched none of the channels.
std::vector<std::string> unmatched(const ExrSelection& selection, const std::vector<std::string>& channels) {
  std::vector<std::string> missing;
  for (const auto& s : selection.layers) {
    ExrSelection one{{s}};
    bool found = false;
    for (const auto& c : channels) found = found || selected(one, c);
    if (!found) missing.push_back(s);
  }
  return missing;
}

// What --layer can name, as select_layers lists it (temporal/core/image.h): rgb, then the layers in file order.
std::string describe_layers(const std::vector<std::string>& channels) {
  std::string text;
  for (const auto& l : layer_names(channels)) text += (text.empty() ? "" : ", ") + l;
  return text.empty() ? "none" : text;
}

std::string oiio_error(const std::string& fallback) {
  std::string e = OIIO::geterror();
  if (e.empty()) e = fallback;
  // OIIO prefixes messages with the file name we already print.
  while (!e.empty() && (e.back() == '\n' || e.back() == ' ')) e.pop_back();
  return e;
}

// --- metadata <-> header ------------------------------------------------------------------------------

void put_matrix(ImageSpec& spec, const char* name, const glm::mat4& m) {
  // OpenEXR stores row-vector matrices (p' = p M). glm is column-vector and column-major, so its memory is
  // already the row-major layout of the transposed matrix: copy it unchanged.
  spec.attribute(name, OIIO::TypeMatrix44, glm::value_ptr(m));
}

void write_metadata(ImageSpec& spec, const FrameMetadata& md) {
  if (md.world_to_camera) put_matrix(spec, "worldToCamera", *md.world_to_camera);
  if (md.world_to_ndc) put_matrix(spec, "worldToNDC", *md.world_to_ndc);
  if (md.near_clip) spec.attribute("clipNear", *md.near_clip);
  if (md.far_clip) spec.attribute("clipFar", *md.far_clip);
  if (md.frame) spec.attribute("temporal:frame", *md.frame);
  if (md.fps) {
    spec.attribute("temporal:fps", float(*md.fps));
    // OpenEXR's standard framesPerSecond (a rational) too, for tools that read only the standard attributes
    // (ffmpeg, Nuke, oiiotool): fps as a fraction with denominator 1000 (or 1001 for the NTSC rates), reduced.
    const double fps = *md.fps;
    if (std::isfinite(fps) && fps > 0.0 && fps < 1e6) {
      const double ntsc_num = fps * 1001.0;  // 29.97 = 30000/1001: an integer multiple of 1000 over 1001
      const bool ntsc = std::abs(fps - std::round(fps)) > 1e-6 &&
                        std::abs(ntsc_num / 1000.0 - std::round(ntsc_num / 1000.0)) < 1e-6;
      const long long den = ntsc ? 1001 : 1000;
      const long long whole = std::llround(fps * double(den));
      const long long g = std::gcd(whole, den);
      const int rational[2] = {int(whole / g), int(den / g)};
      spec.attribute("FramesPerSecond", OIIO::TypeRational, rational);
    }
  }
  // Every file holds scene-linear Rec.709 (docs/conventions.md): say so with OpenEXR's standard chromaticities
  // (red, green, blue primaries and the D65 white point, CIE xy), so other tools need not assume it.
  static const float kRec709[8] = {0.64f, 0.33f, 0.30f, 0.60f, 0.15f, 0.06f, 0.3127f, 0.3290f};
  spec.attribute("chromaticities", TypeDesc(TypeDesc::FLOAT, 8), kRec709);
  if (md.time) spec.attribute("temporal:time", float(*md.time));
  if (md.jitter) spec.attribute("temporal:jitter", TypeDesc(TypeDesc::FLOAT, TypeDesc::VEC2), glm::value_ptr(*md.jitter));
  if (md.jitter_factor) spec.attribute("temporal:jitterFactor", *md.jitter_factor);
  if (md.jitter_index) spec.attribute("temporal:jitterIndex", *md.jitter_index);
  if (md.camera_cut) spec.attribute("temporal:cameraCut", *md.camera_cut ? 1 : 0);
  if (md.compute_ms) spec.attribute("temporal:computeMs", float(*md.compute_ms));
  if (!md.tool.empty()) spec.attribute("temporal:tool", md.tool);
  if (!md.parameters.empty()) spec.attribute("temporal:parameters", md.parameters);
  for (const auto& [name, ms] : md.timings_ms) spec.attribute("temporal:ms:" + name, float(ms));
  for (const auto& [key, value] : md.extra) spec.attribute("temporal:" + key, value);
}

std::optional<glm::mat4> get_matrix(const ImageSpec& spec, const char* name) {
  const OIIO::ParamValue* p = spec.find_attribute(name, OIIO::TypeMatrix44, false);
  if (!p) return std::nullopt;
  glm::mat4 m;
  std::memcpy(glm::value_ptr(m), p->data(), sizeof(float) * 16);
  return m;
}

std::optional<float> get_float(const ImageSpec& spec, const char* name) {
  const OIIO::ParamValue* p = spec.find_attribute(name, TypeDesc::UNKNOWN, false);
  if (!p || p->type().aggregate != TypeDesc::SCALAR) return std::nullopt;
  return p->get_float();
}

std::optional<int> get_int(const ImageSpec& spec, const char* name) {
  const OIIO::ParamValue* p = spec.find_attribute(name, TypeDesc::UNKNOWN, false);
  if (!p || p->type().aggregate != TypeDesc::SCALAR) return std::nullopt;
  return p->get_int();
}

FrameMetadata read_metadata(const ImageSpec& spec) {
  FrameMetadata md;
  md.world_to_camera = get_matrix(spec, "worldToCamera");
  md.world_to_ndc = get_matrix(spec, "worldToNDC");
  md.near_clip = get_float(spec, "clipNear");
  md.far_clip = get_float(spec, "clipFar");
  md.frame = get_int(spec, "temporal:frame");
  if (auto v = get_float(spec, "temporal:fps")) md.fps = *v;
  if (auto v = get_float(spec, "temporal:time")) md.time = *v;
  if (const auto* p = spec.find_attribute("temporal:jitter", TypeDesc::UNKNOWN, false);
      p && p->type().basetype == TypeDesc::FLOAT && p->type().basevalues() == 2) {
    const auto* f = static_cast<const float*>(p->data());
    md.jitter = glm::vec2(f[0], f[1]);
  }
  md.jitter_factor = get_int(spec, "temporal:jitterFactor");
  md.jitter_index = get_int(spec, "temporal:jitterIndex");
  if (auto v = get_int(spec, "temporal:cameraCut")) md.camera_cut = *v != 0;
  if (auto v = get_float(spec, "temporal:computeMs")) md.compute_ms = *v;
  static const std::set<std::string> known = {"temporal:frame",       "temporal:fps",         "temporal:time",
                                              "temporal:jitter",      "temporal:jitterFactor", "temporal:jitterIndex",
                                              "temporal:cameraCut",   "temporal:computeMs",   "temporal:tool",
                                              "temporal:parameters"};
  md.tool = spec.get_string_attribute("temporal:tool");
  md.parameters = spec.get_string_attribute("temporal:parameters");
  for (const auto& p : spec.extra_attribs) {
    const std::string name = p.name().string();
    if (name.rfind("temporal:", 0) != 0 || known.count(name)) continue;
    if (name.rfind("temporal:ms:", 0) == 0 && p.type().aggregate == TypeDesc::SCALAR)
      md.timings_ms[name.substr(12)] = p.get_float();
    else if (p.type() == OIIO::TypeString)
      md.extra[name.substr(9)] = p.get_string();
  }
  return md;
}

const char* compression_name(ExrCompression c) {
  switch (c) {
    case ExrCompression::None: return "none";
    case ExrCompression::Zip: return "zip";
    case ExrCompression::Piz: return "piz";
    case ExrCompression::Dwaa: return "dwaa";
  }
  return "zip";
}

struct Part {
  std::string name;
  std::vector<std::string> channels;
  bool uint_data = false;
  bool half = false;
};

// What a file that is not OpenEXR is, from its first bytes (for a message that says how to fix it).
std::string foreign_format(const unsigned char* b, std::size_t n) {
  if (n >= 8 && std::memcmp(b, "\x89PNG\r\n\x1a\n", 8) == 0) return "PNG";
  if (n >= 3 && b[0] == 0xFF && b[1] == 0xD8 && b[2] == 0xFF) return "JPEG";
  if (n >= 4 && (std::memcmp(b, "II*\0", 4) == 0 || std::memcmp(b, "MM\0*", 4) == 0)) return "TIFF";
  if (n >= 2 && b[0] == '#' && b[1] == 'u') return "USD text";
  return {};
}

// Largest image the tools accept: 16384 x 16384 pixels per part (1 GiB per float channel).
constexpr std::int64_t kMaxPixels = std::int64_t(16384) * 16384;
constexpr int kMaxSide = 65536;

// Walks the attribute list of every header (name, type, 4-byte size, value) without reading the values, and
// refuses an attribute whose declared size is negative or runs past the end of the file. OpenEXR's C++ reader
// (which OpenImageIO uses) allocates a string attribute's declared size before it reads it: a 12 kB file that
// declares a 1.8 GB `temporal:tool` made it allocate 1.8 GB (found by tests/fuzz/exr_fuzz). Reads only the headers.
// The bytes of an EXR being read: a file (`path`), or a buffer in memory (`memory`, named `path` in messages: the
// fuzz target reads its inputs this way, without a file per execution). Sequential reads for the header walk, and
// OpenEXR's positioned reads (exr_read_func_ptr_t) for its core.
struct ExrSource {
  std::string path;
  std::span<const std::uint8_t> memory = {};
  bool in_memory = false;
  std::FILE* file = nullptr;  // the header walk's stream (files)
  std::uint64_t position = 0;  // the header walk's position (memory)

  int get() {
    if (!in_memory) return std::fgetc(file);
    return position < memory.size() ? int(memory[position++]) : EOF;
  }
  bool read(unsigned char* out, std::size_t n) {
    if (!in_memory) return std::fread(out, 1, n, file) == n;
    if (position + n > memory.size()) return false;
    std::memcpy(out, memory.data() + position, n);
    position += n;
    return true;
  }
  long tell() const { return in_memory ? long(position) : std::ftell(file); }
  bool seek(long offset, int whence) {
    if (!in_memory) return std::fseek(file, offset, whence) == 0;
    const long base = whence == SEEK_SET ? 0 : long(position);
    if (offset < 0 || base + offset < 0) return false;
    position = std::uint64_t(base + offset);  // past the end is allowed, as fseek does; reads then fail
    return true;
  }
};

Status check_exr_attributes(ExrSource& src, std::uint64_t size, bool multipart) {
  const std::string& path = src.path;
  auto corrupt = [&](const std::string& what) {
    return Error::input(path, "has a corrupt header (" + what + "): the file is damaged; write it again");
  };
  auto read_name = [&](std::string& out) -> bool {  // a NUL-terminated name of at most 255 characters
    out.clear();
    for (int c; (c = src.get()) != EOF;) {
      if (c == 0) return true;
      if (out.size() >= 255) return false;
      out.push_back(char(c));
    }
    return false;
  };
  if (!src.seek(8, SEEK_SET)) return corrupt("no header");
  std::string name, type;
  for (int part = 0;; ++part) {
    int attributes = 0;
    for (;; ++attributes) {
      if (!read_name(name)) return corrupt("an attribute name is not terminated");
      if (name.empty()) break;  // end of this header
      if (!read_name(type)) return corrupt("the type of attribute '" + name + "' is not terminated");
      unsigned char b[4];
      if (!src.read(b, 4)) return corrupt("attribute '" + name + "' has no size");
      const std::int32_t declared = std::int32_t(std::uint32_t(b[0]) | std::uint32_t(b[1]) << 8 |
                                                 std::uint32_t(b[2]) << 16 | std::uint32_t(b[3]) << 24);
      const long at = src.tell();
      if (declared < 0 || at < 0 || std::uint64_t(at) + std::uint64_t(declared) > size)
        return corrupt("attribute '" + name + "' declares " + std::to_string(declared) + " bytes, more than the file holds");
      if (!src.seek(declared, SEEK_CUR)) return corrupt("attribute '" + name + "'");
    }
    if (!multipart) return Status::ok();
    if (attributes == 0) return Status::ok();  // the empty header that ends a multi-part file's headers
    if (part > 100000) return corrupt("too many parts");
  }
}

// Checks, before any pixel is allocated, that `path` is an OpenEXR file whose parts are complete: the magic number,
// sane part sizes, and for every part the last chunk (scanline block or tile) lies inside the file. A multi-part
// file truncated in a part that the caller does not read is caught here (reading only the needed parts would
// otherwise accept it). Cost: the headers, the chunk tables and one chunk leader per part.
Status check_exr_structure(ExrSource& src) {
  const std::string& path = src.path;
  std::uint64_t size = src.memory.size();
  unsigned char magic[8] = {};
  std::size_t got = 0;
  if (src.in_memory) {
    got = std::min(sizeof magic, src.memory.size());
    if (got) std::memcpy(magic, src.memory.data(), got);
  } else {
    std::error_code ec;
    if (fs::is_directory(path, ec)) return Error::input(path, "is a folder, not an OpenEXR file");
    if (!fs::exists(path, ec)) return Error::input(path, ec ? "cannot be examined: " + ec.message() : "no such file");
    size = fs::file_size(path, ec);
    if (FILE* f = std::fopen(path.c_str(), "rb")) {
      got = std::fread(magic, 1, sizeof magic, f);
      std::fclose(f);
    } else {
      return Error::input(path, "cannot open for reading (permissions?)");
    }
  }
  if (got < 4 || !(magic[0] == 0x76 && magic[1] == 0x2f && magic[2] == 0x31 && magic[3] == 0x01)) {
    const std::string what = foreign_format(magic, got);
    if (what == "PNG" || what == "JPEG" || what == "TIFF")
      return Error::input(path, "is a " + what + " image, not OpenEXR: the tools need scene-linear OpenEXR; convert it "
                                "with `oiiotool IN --colorconvert sRGB linear -o OUT.exr` if it is sRGB-encoded");
    return Error::input(path, std::string("is not an OpenEXR file") + (what.empty() ? "" : " (it looks like " + what + ")") +
                                  (got < 4 ? ": it is empty or truncated" : ""));
  }
  const bool multipart = (magic[5] & 0x10) != 0;  // version field bit 12: multi-part
  if (src.in_memory) {
    src.position = 0;
    if (const Status st = check_exr_attributes(src, size, multipart); !st) return st;
  } else if (std::FILE* f = std::fopen(path.c_str(), "rb")) {
    src.file = f;
    const Status st = check_exr_attributes(src, size, multipart);
    src.file = nullptr;
    std::fclose(f);
    if (!st) return st;
  }
  exr_context_t ctx = nullptr;
  exr_context_initializer_t init = EXR_DEFAULT_CONTEXT_INITIALIZER;
  init.error_handler_fn = [](exr_const_context_t, exr_result_t, const char*) {};  // we word the errors ourselves
  if (src.in_memory) {  // OpenEXR's positioned reads and size query over the buffer
    init.user_data = &src.memory;
    init.read_fn = [](exr_const_context_t, void* user, void* buffer, uint64_t n, uint64_t offset,
                      exr_stream_error_func_ptr_t) -> int64_t {
      const auto& m = *static_cast<const std::span<const std::uint8_t>*>(user);
      if (offset >= m.size()) return 0;
      const uint64_t count = std::min<uint64_t>(n, m.size() - offset);
      std::memcpy(buffer, m.data() + offset, count);
      return int64_t(count);
    };
    init.size_fn = [](exr_const_context_t, void* user) -> int64_t {
      return int64_t(static_cast<const std::span<const std::uint8_t>*>(user)->size());
    };
  }
  if (exr_start_read(&ctx, path.c_str(), &init) != EXR_ERR_SUCCESS) {
    exr_finish(&ctx);
    return Error::input(path, "cannot read the OpenEXR header: the file is truncated or corrupt");
  }
  struct Finish {
    exr_context_t& c;
    ~Finish() { exr_finish(&c); }
  } finish{ctx};
  int parts = 0;
  if (exr_get_count(ctx, &parts) != EXR_ERR_SUCCESS || parts < 1)
    return Error::input(path, "has no image part: the file is corrupt");
  for (int p = 0; p < parts; ++p) {
    exr_attr_box2i_t dw{};
    exr_storage_t storage{};
    if (exr_get_data_window(ctx, p, &dw) != EXR_ERR_SUCCESS || exr_get_storage(ctx, p, &storage) != EXR_ERR_SUCCESS)
      return Error::input(path, "part " + std::to_string(p) + " has a corrupt header");
    const std::int64_t w = std::int64_t(dw.max.x) - dw.min.x + 1, h = std::int64_t(dw.max.y) - dw.min.y + 1;
    if (w < 1 || h < 1 || w > kMaxSide || h > kMaxSide || w * h > kMaxPixels)
      return Error::input(path, "part " + std::to_string(p) + " declares " + std::to_string(w) + "x" +
                                    std::to_string(h) + " pixels: the tools read at most 16384x16384 per image "
                                    "(a corrupt header, or an image to crop or scale down first)");
    // The chunkCount attribute (required in multi-part files) must be the number of chunks the part has: a negative
    // one was read past (the readers count chunks from the data window) and the file accepted with exit 0 (issue
    // 26); a file that disagrees with itself is corrupt. Scanline parts: ceil(height / scanlines per chunk).
    if (std::int32_t declared = 0; exr_attr_get_int(ctx, p, "chunkCount", &declared) == EXR_ERR_SUCCESS) {
      std::int32_t lines = 0;
      std::int64_t expected = -1;
      if (storage == EXR_STORAGE_SCANLINE && exr_get_scanlines_per_chunk(ctx, p, &lines) == EXR_ERR_SUCCESS && lines > 0)
        expected = (h + lines - 1) / lines;
      if (declared < 1 || (expected > 0 && declared != expected))
        return Error::input(path, "part " + std::to_string(p) + " declares " + std::to_string(declared) + " chunks" +
                                      (expected > 0 ? " but its data window holds " + std::to_string(expected) : "") +
                                      " (chunkCount): the file is corrupt; write it again");
    }
    exr_chunk_info_t last{};
    exr_result_t r = EXR_ERR_SUCCESS;
    if (storage == EXR_STORAGE_SCANLINE) {
      r = exr_read_scanline_chunk_info(ctx, p, dw.max.y, &last);
    } else if (storage == EXR_STORAGE_TILED) {
      uint32_t tx = 0, ty = 0;
      exr_tile_level_mode_t level = EXR_TILE_ONE_LEVEL;
      exr_tile_round_mode_t round = EXR_TILE_ROUND_DOWN;
      if (exr_get_tile_descriptor(ctx, p, &tx, &ty, &level, &round) == EXR_ERR_SUCCESS && tx > 0 && ty > 0)
        r = exr_read_tile_chunk_info(ctx, p, int((w - 1) / tx), int((h - 1) / ty), 0, 0, &last);
    } else {
      continue;  // deep data: not produced or read by the tools
    }
    if (r != EXR_ERR_SUCCESS || last.data_offset + last.packed_size > size)
      return Error::input(path, "is truncated or corrupt: part " + std::to_string(p) +
                                    " ends beyond the end of the file (" + std::to_string(size) +
                                    " bytes); write it again");
  }
  return Status::ok();
}

// Output files must be OpenEXR: refuse another extension rather than write EXR bytes under a misleading name.
Status check_exr_extension(const std::string& path) {
  std::string ext = fs::path(path).extension().string();
  for (auto& c : ext) c = char(std::tolower(static_cast<unsigned char>(c)));
  if (ext == ".exr") return Status::ok();
  return Error::usage("output '" + path + "' must end in .exr: the tools write OpenEXR (use compare --png for pictures)");
}

}  // namespace

Expected<ExrCompression> parse_compression(const std::string& name) {
  if (name == "none") return ExrCompression::None;
  if (name == "zip") return ExrCompression::Zip;
  if (name == "piz") return ExrCompression::Piz;
  if (name == "dwaa") return ExrCompression::Dwaa;
  return Error::usage("unknown compression '" + name + "': use none, zip, piz or dwaa (dwaa applies to colour only)");
}

namespace {

// OpenImageIO's reader of the source: the file, or the buffer through an IOMemReader (`proxy`, which must outlive
// the reader). The name must end in .exr either way (OpenImageIO picks the format by it).
std::unique_ptr<ImageInput> open_input(const ExrSource& src, std::unique_ptr<OIIO::Filesystem::IOMemReader>& proxy) {
  if (!src.in_memory) return ImageInput::open(src.path);
  proxy = std::make_unique<OIIO::Filesystem::IOMemReader>(src.memory.data(), src.memory.size());
  return ImageInput::open(src.path, nullptr, proxy.get());
}

ExrSource memory_source(std::span<const std::uint8_t> bytes, const std::string& name) {
  ExrSource src;
  src.path = name;
  src.memory = bytes;
  src.in_memory = true;
  return src;
}

Expected<ExrInfo> read_info(ExrSource& src) {
  const std::string& path = src.path;
  if (Status st = check_exr_structure(src); !st) return st.error();
  std::unique_ptr<OIIO::Filesystem::IOMemReader> proxy;
  auto in = open_input(src, proxy);
  if (!in) return Error::input(path, "cannot read as OpenEXR: " + oiio_error("unknown error") + " (is it truncated or corrupt?)");
  ExrInfo info;
  const ImageSpec& first = in->spec();
  info.width = first.width;
  info.height = first.height;
  info.metadata = read_metadata(first);
  for (int s = 0; in->seek_subimage(s, 0); ++s)
    for (const auto& c : in->spec().channelnames) info.channels.push_back(c);
  return info;
}

Expected<Image> read_image(ExrSource& src, const ExrSelection& selection) {
  const std::string& path = src.path;
  if (Status st = check_exr_structure(src); !st) return st.error();
  std::unique_ptr<OIIO::Filesystem::IOMemReader> proxy;
  auto in = open_input(src, proxy);
  if (!in) return Error::input(path, "cannot read as OpenEXR: " + oiio_error("unknown error") + " (is it truncated or corrupt?)");

  const ImageSpec first = in->spec();
  Image image(first.width, first.height);
  image.metadata() = read_metadata(first);

  std::vector<std::string> all_channels;
  std::vector<float> scratch;
  std::vector<std::uint32_t> scratch_uint;
  for (int s = 0; in->seek_subimage(s, 0); ++s) {
    const ImageSpec& spec = in->spec();
    for (const auto& c : spec.channelnames) all_channels.push_back(c);
    if (spec.width != first.width || spec.height != first.height)
      return Error::input(path, "part " + std::to_string(s) + " is " + std::to_string(spec.width) + "x" +
                                    std::to_string(spec.height) + " but part 0 is " + std::to_string(first.width) +
                                    "x" + std::to_string(first.height) + "; the tools need equal-size parts");
    // The tools index pixels from the display window's corner: a shifted or cropped data window would be read
    // as if it started there (an image shifted by (10, 7) scored inf dB against its original).
    if (spec.x != spec.full_x || spec.y != spec.full_y || spec.width != spec.full_width ||
        spec.height != spec.full_height)
      return Error::input(path, "part " + std::to_string(s) + " has the data window (" + std::to_string(spec.x) + "," +
                                    std::to_string(spec.y) + ")-(" + std::to_string(spec.x + spec.width - 1) + "," +
                                    std::to_string(spec.y + spec.height - 1) + ") inside the display window (" +
                                    std::to_string(spec.full_x) + "," + std::to_string(spec.full_y) + ")-(" +
                                    std::to_string(spec.full_x + spec.full_width - 1) + "," +
                                    std::to_string(spec.full_y + spec.full_height - 1) +
                                    "); the tools need the two equal: pad or crop it with `oiiotool IN --croptofull -o OUT`");
    // Integer channels are ids (`id`, `prev.id`, `history.id`, ...); any other one stored as an integer (colour as
    // uint32) would reach code that reads it as float: refuse it by name.
    for (int k = 0; k < spec.nchannels; ++k) {
      const std::string& name = spec.channelnames[k];
      const auto base = spec.channelformat(k).basetype;
      const bool integer = base == TypeDesc::UINT32 || base == TypeDesc::INT32 || base == TypeDesc::UINT16 ||
                           base == TypeDesc::INT16 || base == TypeDesc::UINT8 || base == TypeDesc::INT8;
      const bool id = name == "id" || (name.size() > 3 && name.compare(name.size() - 3, 3, ".id") == 0);
      if (integer && !id && selected(selection, name))
        return Error::input(path, "channel '" + name + "' is stored as " + spec.channelformat(k).c_str() +
                                      "; only id channels are integers here, colour and data are half or float: "
                                      "convert it with `oiiotool IN -d half -o OUT`");
    }
    // Contiguous runs of selected channels with one pixel type are read in one call each.
    const int nch = spec.nchannels;
    int c = 0;
    while (c < nch) {
      if (!selected(selection, spec.channelnames[c]) || image.has_channel(spec.channelnames[c])) {
        ++c;
        continue;
      }
      const TypeDesc type = spec.channelformat(c);
      const bool as_uint = type.basetype == TypeDesc::UINT32 || type.basetype == TypeDesc::INT32;
      int end = c + 1;
      while (end < nch && selected(selection, spec.channelnames[end]) && !image.has_channel(spec.channelnames[end]) &&
             ((spec.channelformat(end).basetype == TypeDesc::UINT32 || spec.channelformat(end).basetype == TypeDesc::INT32) == as_uint))
        ++end;
      const int n = end - c;
      const std::size_t count = image.pixel_count();
      if (n == 1) {
        // One channel: read straight into its plane, no scratch copy.
        void* dst = as_uint ? static_cast<void*>(image.add_uint_channel(spec.channelnames[c]))
                            : static_cast<void*>(image.add_channel(spec.channelnames[c]));
        if (!in->read_image(s, 0, c, end, as_uint ? OIIO::TypeUInt : OIIO::TypeFloat, dst))
          return Error::input(path, "cannot read channel " + spec.channelnames[c] + ": " +
                                        oiio_error(in->geterror()) + " (is the file truncated or corrupt?)");
      } else if (as_uint) {
        scratch_uint.resize(count * n);
        if (!in->read_image(s, 0, c, end, OIIO::TypeUInt, scratch_uint.data()))
          return Error::input(path, "cannot read part " + std::to_string(s) + ": " + oiio_error(in->geterror()) +
                                        " (is the file truncated or corrupt?)");
        for (int k = 0; k < n; ++k) {
          std::uint32_t* dst = image.add_uint_channel(spec.channelnames[c + k]);
          for (std::size_t i = 0; i < count; ++i) dst[i] = scratch_uint[i * n + k];
        }
      } else {
        scratch.resize(count * n);
        if (!in->read_image(s, 0, c, end, OIIO::TypeFloat, scratch.data()))
          return Error::input(path, "cannot read part " + std::to_string(s) + ": " + oiio_error(in->geterror()) +
                                        " (is the file truncated or corrupt?)");
        std::vector<std::string> names(spec.channelnames.begin() + c, spec.channelnames.begin() + end);
        if (auto st = image.from_interleaved(names, scratch); !st) return Error::input(path, st.error().message);
      }
      c = end;
    }
  }
  if (auto missing = unmatched(selection, all_channels); !missing.empty()) {
    std::string list;
    for (const auto& m : missing) list += (list.empty() ? "" : ", ") + m;
    return Error::input(path, "no layer '" + list + "' (have: " + describe_layers(all_channels) +
                                  "); produce it upstream (e.g. render-gbuffer --outputs) or pick another --layer");
  }
  return image;
}

}  // namespace

Expected<ExrInfo> read_exr_info(const std::string& path) {
  ExrSource src{.path = path};
  return read_info(src);
}

Expected<ExrInfo> read_exr_info(std::span<const std::uint8_t> bytes, const std::string& name) {
  ExrSource src = memory_source(bytes, name);
  return read_info(src);
}

Expected<Image> read_exr(const std::string& path, const ExrSelection& selection) {
  ExrSource src{.path = path};
  return read_image(src, selection);
}

Expected<Image> read_exr(std::span<const std::uint8_t> bytes, const std::string& name, const ExrSelection& selection) {
  ExrSource src = memory_source(bytes, name);
  return read_image(src, selection);
}

Status write_exr(const std::string& path, const Image& image, const ExrWriteOptions& options) {
  if (Status st = check_exr_extension(path); !st) return st;
  if (image.empty()) return Error::output(path, "refusing to write an empty image");
  if (image.channel_count() == 0) return Error::output(path, "refusing to write an image without channels");

  // Group channels into parts: the colour part first (viewers and idiff show part 0), then one per layer.
  std::vector<Part> parts;
  std::map<std::string, std::size_t> part_of_layer;
  auto part_for = [&](const std::string& layer, bool uint_data) -> Part& {
    const std::string key = (layer.empty() ? std::string(kColourPart) : layer) + (uint_data ? "#u" : "");
    auto it = part_of_layer.find(key);
    if (it == part_of_layer.end()) {
      std::string name = layer.empty() ? std::string(kColourPart) : layer;
      if (uint_data && !layer.empty()) name = layer;
      it = part_of_layer.emplace(key, parts.size()).first;
      parts.push_back(Part{name, {}, uint_data, false});
    }
    return parts[it->second];
  };
  // Bare channels: colour R,G,B,A share the colour part; any other bare channel (id, Z) gets its own part.
  for (const auto& name : image.channel_names()) {
    const bool is_uint = image.channel_type(name) == ChannelType::UInt;
    std::string layer = layer_of(name);
    if (layer.empty() && !is_colour_channel(name)) layer = name;
    part_for(layer, is_uint).channels.push_back(name);
  }
  std::stable_partition(parts.begin(), parts.end(), [](const Part& p) { return p.name == kColourPart; });
  // Part names must be unique in a multi-part file.
  std::set<std::string> names_seen;
  for (auto& p : parts) {
    while (!names_seen.insert(p.name).second) p.name += "_";
    for (const auto& h : options.half_layers)
      if (!p.uint_data && (h == p.name || (h == "rgba" && p.name == kColourPart) ||
                           std::find(p.channels.begin(), p.channels.end(), h) != p.channels.end()))
        p.half = true;
  }

  std::vector<ImageSpec> specs;
  for (const auto& p : parts) {
    const TypeDesc format = p.uint_data ? OIIO::TypeUInt : (p.half ? OIIO::TypeHalf : OIIO::TypeFloat);
    ImageSpec spec(image.width(), image.height(), int(p.channels.size()), format);
    spec.channelnames = p.channels;
    spec.alpha_channel = -1;
    for (std::size_t i = 0; i < p.channels.size(); ++i)
      if (p.channels[i] == "A") spec.alpha_channel = int(i);
    spec.attribute("oiio:subimagename", p.name);
    // DWA is lossy and treats any `*.Y` channel as luminance: colour only, data stays lossless.
    const ExrCompression c =
        options.compression == ExrCompression::Dwaa && p.name != kColourPart ? ExrCompression::Zip : options.compression;
    spec.attribute("compression", compression_name(c));
    write_metadata(spec, image.metadata());
    specs.push_back(std::move(spec));
  }

  // Hidden temporary file beside the target (temporal/io/atomic_file.h), renamed over it when complete.
  TemporaryFile file(path);
  const std::string& tmp = file.path();

  auto out = ImageOutput::create("openexr");
  if (!out) return Error::output(path, "OpenImageIO has no OpenEXR writer: " + oiio_error("unknown error"));
  const bool multi = specs.size() > 1;
  if (multi && !out->supports("multiimage"))
    return Error::output(path, "this OpenImageIO cannot write multi-part EXR");
  bool ok = multi ? out->open(tmp, int(specs.size()), specs.data()) : out->open(tmp, specs[0]);
  std::vector<float> buffer;
  std::vector<std::uint32_t> buffer_uint;
  for (std::size_t s = 0; ok && s < parts.size(); ++s) {
    if (s > 0) ok = out->open(tmp, specs[s], ImageOutput::AppendSubimage);
    if (!ok) break;
    const Part& p = parts[s];
    const std::size_t n = p.channels.size(), count = image.pixel_count();
    if (p.uint_data) {
      const void* data = nullptr;
      if (n == 1) {
        data = image.uint_plane(p.channels[0]);
      } else {
        buffer_uint.resize(count * n);
        for (std::size_t k = 0; k < n; ++k) {
          const std::uint32_t* src = image.uint_plane(p.channels[k]);
          for (std::size_t i = 0; i < count; ++i) buffer_uint[i * n + k] = src[i];
        }
        data = buffer_uint.data();
      }
      ok = out->write_image(OIIO::TypeUInt, data);
    } else {
      const void* data = nullptr;
      if (n == 1) {
        data = image.plane(p.channels[0]);
      } else {
        buffer.resize(count * n);
        if (auto st = image.to_interleaved(p.channels, buffer); !st) return Error::output(path, st.error().message);
        data = buffer.data();
      }
      ok = out->write_image(OIIO::TypeFloat, data);
    }
  }
  const std::string write_error = ok ? std::string() : out->geterror();
  ok = out->close() && ok;
  out.reset();
  if (!ok)
    return Error::output(path, "cannot write: " + (write_error.empty() ? oiio_error("unknown error") : write_error) +
                                   " (is the disk full or the folder read-only?)");
  // OpenEXR's stream does not report every failed write (a full disk gave a truncated file and no error), so the
  // finished temporary file is checked the way inputs are - every part's last chunk inside the file - before it
  // may take the final name. Cost: one header read of a file that is in the page cache.
  ExrSource written{.path = tmp};
  if (Status s = check_exr_structure(written); !s)
    return Error::output(path, "the file written is incomplete (is the disk full or a file-size limit reached?): " +
                                   s.error().message);
  return file.commit();
}

Expected<Image> read_exr_rgb(const std::string& path) { return read_exr(path, ExrSelection{{"rgb"}}); }

}  // namespace temporal
