// compare --frames with oiiotool's stepped lists: `0-5y3` scores frames 1, 2, 4, 5 only (the in-between frames of
// a 3x frame-rate study, whose rendered frames 0 and 3 equal the reference and would make the mean infinite),
// and the flicker of a compared frame after a gap is still its change from the frame just before it.
#include "temporal/io/exr.h"

#include "test_support.h"

#include <nlohmann/json.hpp>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <sstream>

namespace temporal {
namespace {

namespace fs = std::filesystem;

Image flat(float value) {
  Image img(24, 16);
  for (const char* c : {"R", "G", "B"}) img.add_channel(c, value);
  return img;
}

TEST(CompareFrames, AllButEveryThirdScoresOnlyTheInBetweenFrames) {
  const fs::path dir = test::scratch_dir("compare_frames_y3");
  for (int f = 0; f <= 5; ++f) {
    char name[32];
    std::snprintf(name, sizeof name, "%04d.exr", f);
    ASSERT_TRUE(write_exr((dir / ("ref." + std::string(name))).string(), flat(0.5f)));
    // Frames 0 and 3 (the "rendered" ones) are exact; the in-between frames are off by 0.01 (40 dB).
    ASSERT_TRUE(write_exr((dir / ("m." + std::string(name))).string(), flat(f % 3 == 0 ? 0.5f : 0.51f)));
  }
  std::string out;
  ASSERT_EQ(test::run_command("cd " + dir.string() + " && env -u DISPLAY " + test::tool_path("compare").string() +
                                  " --reference ref.####.exr m.####.exr --frames 0-5y3 --json m.json --csv m.csv",
                              &out),
            0)
      << out;
  std::ifstream in(dir / "m.json");
  const auto j = nlohmann::json::parse(in);
  std::ostringstream text;
  text << j;
  // Every scored frame is an in-between frame: PSNR 20 log10(1 / 0.01) = 40 dB exactly, a finite mean.
  std::ifstream csv(dir / "m.csv");
  std::string header, line;
  std::getline(csv, header);
  std::vector<int> frames;
  std::size_t frame_col = 0, col = 0;
  for (std::stringstream h(header); std::getline(h, line, ','); ++col)
    if (line == "frame") frame_col = col;
  while (std::getline(csv, line)) {
    std::stringstream cells(line);
    std::string cell;
    for (std::size_t c = 0; std::getline(cells, cell, ','); ++c)
      if (c == frame_col) frames.push_back(std::stoi(cell));
  }
  EXPECT_EQ(frames, (std::vector<int>{1, 2, 4, 5})) << header;
  EXPECT_EQ(text.str().find("inf"), std::string::npos) << "no infinite value: " << text.str().substr(0, 400);
  EXPECT_NE(text.str().find("40.0"), std::string::npos) << text.str().substr(0, 600);
}

}  // namespace
}  // namespace temporal
