// EXR files the tools must refuse by name rather than misread (issue 26 items 6 and 8): a data window that differs
// from the display window (it would be read as if it started at the corner), and colour stored as uint32 (code
// that reads colour as float would find no plane).
#include "temporal/io/exr.h"

#include "test_support.h"

#include <OpenImageIO/imageio.h>

#include <cstring>
#include <fstream>
#include <iterator>
#include <limits>
#include <tuple>
#include <vector>

namespace temporal {
namespace {

namespace fs = std::filesystem;

// A one-part RGB file written by OpenImageIO directly, with the given data window origin and pixel type.
void write_raw(const fs::path& path, int x, int y, OIIO::TypeDesc type) {
  OIIO::ImageSpec spec(8, 4, 3, type);
  spec.x = x;
  spec.y = y;
  spec.full_x = 0;
  spec.full_y = 0;
  spec.full_width = 8 + x;
  spec.full_height = 4 + y;
  spec.channelnames = {"R", "G", "B"};
  auto out = OIIO::ImageOutput::create(path.string());
  ASSERT_TRUE(out);
  ASSERT_TRUE(out->open(path.string(), spec));
  std::vector<float> pixels(8 * 4 * 3, 0.25f);
  std::vector<std::uint32_t> ints(8 * 4 * 3, 7u);
  ASSERT_TRUE(type == OIIO::TypeFloat ? out->write_image(OIIO::TypeFloat, pixels.data())
                                      : out->write_image(OIIO::TypeUInt, ints.data()));
  ASSERT_TRUE(out->close());
}

TEST(ExrHostile, ShiftedDataWindowIsRefusedByName) {
  const fs::path dir = test::scratch_dir("exr_hostile_window");
  write_raw(dir / "shifted.exr", 10, 7, OIIO::TypeFloat);
  auto r = read_exr((dir / "shifted.exr").string());
  ASSERT_FALSE(r);
  EXPECT_EQ(r.error().kind, ErrorKind::Input);
  EXPECT_NE(r.error().message.find("data window (10,7)"), std::string::npos) << r.error().message;
  EXPECT_NE(r.error().message.find("--croptofull"), std::string::npos) << r.error().message;
  write_raw(dir / "aligned.exr", 0, 0, OIIO::TypeFloat);  // the control: the same file unshifted reads
  auto ok = read_exr((dir / "aligned.exr").string());
  ASSERT_TRUE(ok) << ok.error().message;
  EXPECT_FLOAT_EQ(ok->plane("G")[5], 0.25f);
}

TEST(ExrHostile, ColourStoredAsIntegersIsRefusedButIdsAreRead) {
  const fs::path dir = test::scratch_dir("exr_hostile_uint");
  write_raw(dir / "uint.exr", 0, 0, OIIO::TypeUInt);
  auto r = read_exr((dir / "uint.exr").string());
  ASSERT_FALSE(r);
  EXPECT_EQ(r.error().kind, ErrorKind::Input);
  EXPECT_NE(r.error().message.find("channel 'R'"), std::string::npos) << r.error().message;
  Image ids(8, 4);
  std::uint32_t* id = ids.add_uint_channel("id");
  for (int i = 0; i < 32; ++i) id[i] = std::uint32_t(i * 1000003);
  ASSERT_TRUE(write_exr((dir / "ids.exr").string(), ids));
  auto back = read_exr((dir / "ids.exr").string());
  ASSERT_TRUE(back) << back.error().message;
  ASSERT_NE(back->uint_plane("id"), nullptr);
  EXPECT_EQ(back->uint_plane("id")[31], 31u * 1000003u);
}

// Beside temporal:fps, the standard attributes other tools read (issue 25 item 8): framesPerSecond as a reduced
// rational, and the Rec.709 / D65 chromaticities of the working space.
TEST(ExrStandardAttributes, FramesPerSecondAndChromaticities) {
  const fs::path dir = test::scratch_dir("exr_standard_attributes");
  for (const auto& [fps, num, den] : {std::tuple{40.0, 40, 1}, std::tuple{120.0, 120, 1}, std::tuple{23.976, 2997, 125},
                                      std::tuple{30000.0 / 1001.0, 30000, 1001}}) {
    Image img = test::make_image(4, 4, {"R", "G", "B"}, 0.5f);
    img.metadata().fps = fps;
    const std::string path = (dir / "a.exr").string();
    ASSERT_TRUE(write_exr(path, img));
    auto in = OIIO::ImageInput::open(path);
    ASSERT_TRUE(in);
    const OIIO::ParamValue* r = in->spec().find_attribute("FramesPerSecond", OIIO::TypeRational);
    ASSERT_NE(r, nullptr) << fps;
    const int* v = static_cast<const int*>(r->data());
    EXPECT_EQ(v[0], num) << fps;
    EXPECT_EQ(v[1], den) << fps;
    const OIIO::ParamValue* c = in->spec().find_attribute("chromaticities");
    ASSERT_NE(c, nullptr);
    ASSERT_EQ(c->type().basevalues(), 8u);
    const float* xy = static_cast<const float*>(c->data());
    EXPECT_FLOAT_EQ(xy[0], 0.64f);
    EXPECT_FLOAT_EQ(xy[7], 0.3290f);
  }
}


// The readers over a buffer in memory (tests/fuzz/exr_fuzz reads its inputs this way) read what the file readers
// read, bit for bit, and refuse what they refuse, naming the buffer by the name given.
TEST(ExrMemory, ReadsWhatTheFileReaderReadsAndRefusesWhatItRefuses) {
  const fs::path dir = test::scratch_dir("exr_memory");
  Image img(9, 5);
  float* r = img.add_channel("R");
  img.add_channel("G", 0.5f);
  img.add_channel("B", 0.25f);
  img.add_channel("depth.Z", 3.0f);
  std::uint32_t* id = img.add_uint_channel("id");
  for (std::size_t i = 0; i < img.pixel_count(); ++i) {
    r[i] = float(i) * 0.125f;
    id[i] = std::uint32_t(i * 7);
  }
  img.metadata().frame = 12;
  ASSERT_TRUE(write_exr((dir / "m.exr").string(), img));
  std::ifstream in(dir / "m.exr", std::ios::binary);
  const std::vector<std::uint8_t> bytes((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  ASSERT_GT(bytes.size(), 100u);
  auto from_file = read_exr((dir / "m.exr").string());
  auto from_memory = read_exr(bytes, "buffer.exr");
  ASSERT_TRUE(from_file && from_memory) << (from_memory ? "" : from_memory.error().message);
  EXPECT_EQ(from_memory->channel_names(), from_file->channel_names());
  for (const auto& c : from_file->channel_names()) {
    if (const float* a = from_file->plane(c)) {
      for (std::size_t i = 0; i < img.pixel_count(); ++i) ASSERT_EQ(a[i], from_memory->plane(c)[i]) << c;
    }
    if (const std::uint32_t* a = from_file->uint_plane(c)) {
      for (std::size_t i = 0; i < img.pixel_count(); ++i) ASSERT_EQ(a[i], from_memory->uint_plane(c)[i]) << c;
    }
  }
  EXPECT_EQ(from_memory->metadata().frame.value_or(-1), 12);
  auto info = read_exr_info(bytes, "buffer.exr");
  ASSERT_TRUE(info);
  EXPECT_EQ(info->width, 9);
  auto depth = read_exr(bytes, "buffer.exr", ExrSelection{{"depth"}});
  ASSERT_TRUE(depth);
  EXPECT_TRUE(depth->plane("depth.Z") && !depth->plane("R"));
  // Truncated in its last chunk, cut inside the header, empty, and another format: refused, naming the buffer.
  for (std::size_t keep : {bytes.size() - 20, std::size_t(40), std::size_t(0)}) {
    const std::vector<std::uint8_t> cut(bytes.begin(), bytes.begin() + std::ptrdiff_t(keep));
    auto r2 = read_exr(cut, "cut.exr");
    ASSERT_FALSE(r2) << keep;
    EXPECT_EQ(r2.error().kind, ErrorKind::Input);
    EXPECT_EQ(r2.error().file, "cut.exr");
    EXPECT_FALSE(read_exr_info(cut, "cut.exr")) << keep;
  }
  const std::vector<std::uint8_t> png = {0x89, 'P', 'N', 'G', '\r', '\n', 0x1a, '\n', 0, 0, 0, 13};
  auto r3 = read_exr(png, "p.exr");
  ASSERT_FALSE(r3);
  EXPECT_NE(r3.error().message.find("PNG"), std::string::npos) << r3.error().message;
}


// Issue 26, "Exit codes that say fine": a multi-part file whose chunkCount attribute is negative (or disagrees with
// its data window) was read with exit 0; it is an input error naming the file and the attribute.
TEST(ExrHostile, AChunkCountThatDisagreesWithTheFileIsRefused) {
  const fs::path dir = test::scratch_dir("exr_hostile_chunks");
  Image img(8, 40);
  img.add_channel("R", 0.5f);
  img.add_channel("G", 0.5f);
  img.add_channel("B", 0.5f);
  img.add_channel("depth.Z", 2.0f);
  ASSERT_TRUE(write_exr((dir / "ok.exr").string(), img));
  std::ifstream in(dir / "ok.exr", std::ios::binary);
  const std::string bytes((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  const std::string key = std::string("chunkCount\0int\0", 15) + std::string("\x04\0\0\0", 4);
  const std::size_t at = bytes.find(key);
  ASSERT_NE(at, std::string::npos) << "a multi-part file has chunkCount";
  ASSERT_TRUE(read_exr((dir / "ok.exr").string()));
  for (std::int32_t bad : {-5, std::numeric_limits<std::int32_t>::min(), 0, 1000}) {
    std::string patched = bytes;
    std::memcpy(&patched[at + key.size()], &bad, 4);  // little-endian, as the file
    const fs::path path = dir / ("bad" + std::to_string(bad) + ".exr");
    std::ofstream(path, std::ios::binary) << patched;
    auto r = read_exr(path.string());
    ASSERT_FALSE(r) << bad;
    EXPECT_EQ(r.error().kind, ErrorKind::Input);
    EXPECT_EQ(r.error().file, path.string());
    EXPECT_NE(r.error().message.find("chunkCount"), std::string::npos) << r.error().message;
    EXPECT_FALSE(read_exr_info(path.string())) << bad;
  }
}

}  // namespace
}  // namespace temporal
