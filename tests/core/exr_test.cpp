#include "temporal/io/exr.h"

#include "test_support.h"

#include <OpenImageIO/imageio.h>

#include <cmath>
#include <fstream>
#include <limits>

namespace temporal {
namespace {

Image sample_gbuffer(int w, int h) {
  Image image(w, h);
  for (const char* c : {"R", "G", "B", "depth.Z", "N.X", "N.Y", "N.Z", "motion.X", "motion.Y"}) {
    float* p = image.add_channel(c);
    for (std::size_t i = 0; i < image.pixel_count(); ++i) p[i] = std::sin(float(i) * 0.37f + float(c[0])) * 3.0f;
  }
  std::uint32_t* id = image.add_uint_channel("id");
  for (std::size_t i = 0; i < image.pixel_count(); ++i) id[i] = std::uint32_t(16777217u + i * 7919u);  // > 2^24
  return image;
}

TEST(Exr, ReadsOnlyTheSelectedLayers) {
  const auto dir = test::scratch_dir("exr_select");
  const Image image = sample_gbuffer(19, 11);
  const std::string path = (dir / "g.exr").string();
  ASSERT_TRUE(write_exr(path, image));
  auto motion = read_exr(path, {{"motion", "id"}});
  ASSERT_TRUE(motion) << motion.error().message;
  EXPECT_EQ(motion->channel_count(), 3u);
  EXPECT_TRUE(motion->has_channel("motion.X"));
  EXPECT_TRUE(motion->has_channel("motion.Y"));
  EXPECT_EQ(motion->channel_type("id"), ChannelType::UInt);
  EXPECT_TRUE(test::images_near(*motion, image, {"motion.X", "motion.Y"}, 0.0f, "exr_select"));
  for (std::size_t i = 0; i < image.pixel_count(); ++i) ASSERT_EQ(motion->uint_plane("id")[i], image.uint_plane("id")[i]);
  auto rgb = read_exr(path, {{"rgb"}});
  ASSERT_TRUE(rgb);
  EXPECT_EQ(rgb->channel_names(), (std::vector<std::string>{"R", "G", "B"}));
}

TEST(Exr, MissingLayerNamesWhatTheFileHas) {
  const auto dir = test::scratch_dir("exr_missing");
  const std::string path = (dir / "g.exr").string();
  ASSERT_TRUE(write_exr(path, sample_gbuffer(4, 4)));
  auto r = read_exr(path, {{"albedo"}});
  ASSERT_FALSE(r);
  EXPECT_EQ(r.error().kind, ErrorKind::Input);
  EXPECT_NE(r.error().message.find("no layer 'albedo'"), std::string::npos) << r.error().message;
  EXPECT_NE(r.error().message.find("motion"), std::string::npos) << r.error().message;
}

TEST(Exr, ColourIsTheFirstPartAndEachLayerItsOwnPart) {
  const auto dir = test::scratch_dir("exr_parts");
  const std::string path = (dir / "g.exr").string();
  ASSERT_TRUE(write_exr(path, sample_gbuffer(4, 4)));
  auto in = OIIO::ImageInput::open(path);
  ASSERT_TRUE(in);
  std::vector<std::string> parts;
  for (int s = 0; in->seek_subimage(s, 0); ++s) parts.push_back(in->spec().get_string_attribute("oiio:subimagename"));
  EXPECT_EQ(parts.front(), "rgba");
  EXPECT_EQ(parts.size(), 5u);  // rgba, depth, N, motion, id
  in->seek_subimage(0, 0);
  EXPECT_EQ(in->spec().get_string_attribute("compression"), "zip");
}

TEST(Exr, HalfLayersAndDwaOnlyOnColour) {
  const auto dir = test::scratch_dir("exr_half");
  const std::string path = (dir / "g.exr").string();
  Image image = sample_gbuffer(16, 16);
  ExrWriteOptions options;
  options.compression = ExrCompression::Dwaa;
  options.half_layers = {"N"};
  ASSERT_TRUE(write_exr(path, image, options));
  auto back = read_exr(path);
  ASSERT_TRUE(back);
  // Data layers stay lossless under a DWA request; N was asked for as half.
  EXPECT_TRUE(test::images_near(*back, image, {"depth.Z", "motion.X", "motion.Y"}, 0.0f, "exr_dwa_data"));
  EXPECT_TRUE(test::images_near(*back, image, {"N.X", "N.Y", "N.Z"}, 3.0f * 1e-3f, "exr_half_n"));
  auto in = OIIO::ImageInput::open(path);
  for (int s = 0; in->seek_subimage(s, 0); ++s) {
    const auto& spec = in->spec();
    const std::string name = spec.get_string_attribute("oiio:subimagename");
    const std::string compression = spec.get_string_attribute("compression");
    if (name == "rgba") EXPECT_EQ(compression.substr(0, 4), "dwaa");
    else EXPECT_EQ(compression, "zip") << name;
  }
}

TEST(Exr, TruncatedAndCorruptFilesAreInputErrors) {
  const auto dir = test::scratch_dir("exr_corrupt");
  const std::string good = (dir / "good.exr").string();
  ASSERT_TRUE(write_exr(good, sample_gbuffer(64, 64)));
  std::ifstream in(good, std::ios::binary);
  std::string bytes((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  ASSERT_GT(bytes.size(), 1000u);

  const std::string truncated = (dir / "truncated.exr").string();
  std::ofstream(truncated, std::ios::binary).write(bytes.data(), std::streamsize(bytes.size() * 2 / 3));
  auto t = read_exr(truncated);
  ASSERT_FALSE(t);
  EXPECT_EQ(t.error().kind, ErrorKind::Input);
  EXPECT_EQ(t.error().file, truncated);

  const std::string garbage = (dir / "garbage.exr").string();
  std::string noise = bytes;
  for (std::size_t i = 400; i < noise.size(); i += 3) noise[i] = char(noise[i] ^ 0x5a);
  std::ofstream(garbage, std::ios::binary).write(noise.data(), std::streamsize(noise.size()));
  auto g = read_exr(garbage);
  ASSERT_FALSE(g);
  EXPECT_EQ(g.error().kind, ErrorKind::Input);

  const std::string text = (dir / "text.exr").string();
  std::ofstream(text) << "not an image";
  EXPECT_FALSE(read_exr(text));
  EXPECT_FALSE(read_exr_info(text));
  EXPECT_FALSE(read_exr((dir / "absent.exr").string()));
}

TEST(Exr, WritesAtomicallyWithoutLeftovers) {
  const auto dir = test::scratch_dir("exr_atomic");
  const std::string path = (dir / "sub" / "out.0001.exr").string();
  ASSERT_TRUE(write_exr(path, sample_gbuffer(8, 8)));
  // Overwrite in place: readers see the old or the new file, never a partial one.
  ASSERT_TRUE(write_exr(path, sample_gbuffer(8, 8)));
  int files = 0;
  for (const auto& e : std::filesystem::directory_iterator(dir / "sub")) {
    ++files;
    EXPECT_EQ(e.path().filename(), "out.0001.exr");
  }
  EXPECT_EQ(files, 1);
  // An unwritable destination is an Output error, and nothing is left behind.
  std::ofstream(dir / "file") << "x";
  auto status = write_exr((dir / "file" / "x.exr").string(), sample_gbuffer(2, 2));
  ASSERT_FALSE(status);
  EXPECT_EQ(status.error().kind, ErrorKind::Output);
}

TEST(Exr, NonFiniteValuesSurviveTheRoundTrip) {
  const auto dir = test::scratch_dir("exr_nonfinite");
  Image image(3, 1);
  float* r = image.add_channel("R");
  r[0] = std::numeric_limits<float>::quiet_NaN();
  r[1] = std::numeric_limits<float>::infinity();
  r[2] = -1e30f;
  ASSERT_TRUE(write_exr((dir / "n.exr").string(), image));
  auto back = read_exr((dir / "n.exr").string());
  ASSERT_TRUE(back);
  EXPECT_TRUE(std::isnan(back->plane("R")[0]));
  EXPECT_TRUE(std::isinf(back->plane("R")[1]));
  EXPECT_EQ(back->plane("R")[2], -1e30f);
  EXPECT_EQ(count_non_finite({back->plane("R"), 3}), 2u);
}

TEST(Exr, ParsesCompressionNames) {
  EXPECT_EQ(*parse_compression("piz"), ExrCompression::Piz);
  EXPECT_FALSE(parse_compression("jpeg"));
}

}  // namespace
}  // namespace temporal
