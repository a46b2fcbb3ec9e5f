// Outputs that cannot be finished never take their final name (docs/cli.md, "Outputs"): a write that fails
// part-way (a full disk, a file-size limit) exits 4, names the file, and leaves neither the file nor its hidden
// temporary behind. The file-size limit (`ulimit -f`) stands in for a full disk without needing root or a tmpfs.
#include "temporal/io/exr.h"
#include "temporal/io/runner.h"

#include "test_support.h"

#include <sys/stat.h>

#include <filesystem>
#include <random>

namespace temporal {
namespace {

namespace fs = std::filesystem;

// Four 64x64 frames of noise: zip cannot compress them below ~40 kB, above the 8 kB limit used below.
void write_noise_frames(const fs::path& dir) {
  std::mt19937 rng(7);
  std::uniform_real_distribution<float> u(0.0f, 1.0f);
  for (int f = 0; f < 4; ++f) {
    Image img = test::make_image(64, 64, {"R", "G", "B"});
    for (const char* c : {"R", "G", "B"}) {
      float* p = img.plane(c);
      for (std::size_t i = 0; i < img.pixel_count(); ++i) p[i] = u(rng);
    }
    char name[32];
    std::snprintf(name, sizeof name, "in.%04d.exr", f);
    ASSERT_TRUE(write_exr((dir / name).string(), img));
  }
}

std::vector<std::string> files_in(const fs::path& dir) {
  std::vector<std::string> names;
  for (const auto& e : fs::directory_iterator(dir)) names.push_back(e.path().filename().string());
  return names;
}

TEST(NothingLost, FileSizeLimitFailsTheWriteWithExitFourAndNoFinalFile) {
  const fs::path dir = test::scratch_dir("nothing_lost_file_size");
  write_noise_frames(dir);
  const fs::path out = dir / "out";
  fs::create_directories(out);
  std::string text;
  const std::string command = "ulimit -f 8; " + test::tool_path("filter-phlm").string() + " --input " +
                              (dir / "in.####.exr").string() + " --out " + (out / "r.####.exr").string() +
                              " --method ema";
  const int rc = test::run_command("bash -c '" + command + "'", &text);
  EXPECT_EQ(rc, 4) << text;
  EXPECT_NE(text.find("r.0000.exr"), std::string::npos) << "the message names the file: " << text;
  EXPECT_TRUE(files_in(out).empty()) << "left behind: " << testing::PrintToString(files_in(out));
}

TEST(NothingLost, WithoutTheLimitTheSameRunWritesEveryFrame) {
  // The control: the limit, not the command, is what fails above.
  const fs::path dir = test::scratch_dir("nothing_lost_control");
  write_noise_frames(dir);
  std::string text;
  ASSERT_EQ(test::run_command(test::tool_path("filter-phlm").string() + " --input " + (dir / "in.####.exr").string() +
                                  " --out " + (dir / "r.####.exr").string() + " --method ema",
                              &text),
            0)
      << text;
  for (int f = 0; f < 4; ++f) {
    char name[32];
    std::snprintf(name, sizeof name, "r.%04d.exr", f);
    EXPECT_TRUE(read_exr((dir / name).string())) << name;
  }
}

// Two outputs of one run may not name the same file: by equal text, another spelling of the folder, or a file
// that a frame pattern produces.
TEST(OutputPaths, RefusesOutputsThatNameTheSameFile) {
  const fs::path dir = test::scratch_dir("output_paths");
  fs::create_directories(dir / "sub");
  {
    OutputPaths o;
    ASSERT_TRUE(o.add((dir / "r.####.exr").string(), "--out"));
    const Status s = o.add((dir / "r.####.exr").string(), "--state-out");
    ASSERT_FALSE(s);
    EXPECT_NE(s.error().message.find("--out"), std::string::npos) << s.error().message;
  }
  {
    OutputPaths o;
    ASSERT_TRUE(o.add((dir / "r.####.exr").string(), "--out"));
    EXPECT_FALSE(o.add((dir / "sub" / ".." / "r.%04d.exr").string(), "--state-out"));  // same folder, same frames
    EXPECT_FALSE(o.add((dir / "r.0007.exr").string(), "--state-out"));                 // one frame of --out
    EXPECT_TRUE(o.add((dir / "state.####.exr").string(), "--state-out"));
    EXPECT_TRUE(o.add((dir / "r.0007.exr.csv").string(), "--csv"));
  }
  {
    OutputPaths o;
    ASSERT_TRUE(o.add((dir / "m.txt").string(), "--csv"));
    EXPECT_FALSE(o.add((dir / "m.txt").string(), "--json"));
  }
}

TEST(OutputPaths, RefusesAnExistingOutputThatIsNotARegularFile) {
  const fs::path dir = test::scratch_dir("output_paths_special");
  const fs::path fifo = dir / "pipe.exr";
  fs::remove(fifo);
  ASSERT_EQ(mkfifo(fifo.c_str(), 0600), 0);
  OutputPaths o;
  const Status s = o.add(fifo.string(), "--out");
  ASSERT_FALSE(s);
  EXPECT_NE(s.error().message.find("not a regular file"), std::string::npos) << s.error().message;
  EXPECT_FALSE(OutputPaths().add(dir.string(), "--csv"));  // a folder
}

TEST(NothingLost, StateOutEqualToOutIsRefusedBeforeAnyWrite) {
  const fs::path dir = test::scratch_dir("nothing_lost_state_out");
  write_noise_frames(dir);
  const fs::path out = dir / "so";
  fs::create_directories(out);
  std::string text;
  const std::string pattern = (out / "r.####.exr").string();
  EXPECT_EQ(test::run_command(test::tool_path("filter-phlm").string() + " --input " + (dir / "in.####.exr").string() +
                                  " --out " + pattern + " --state-out " + pattern + " --method phlm",
                              &text),
            1)
      << text;
  EXPECT_NE(text.find("--state-out"), std::string::npos) << text;
  EXPECT_TRUE(files_in(out).empty()) << "written: " << testing::PrintToString(files_in(out));
}

TEST(NothingLost, AnOutputThatIsAPipeIsRefused) {
  const fs::path dir = test::scratch_dir("nothing_lost_pipe");
  write_noise_frames(dir);
  const fs::path fifo = dir / "pipe.exr";
  fs::remove(fifo);
  ASSERT_EQ(mkfifo(fifo.c_str(), 0600), 0);
  std::string text;
  EXPECT_EQ(test::run_command(test::tool_path("filter-phlm").string() + " --input " + (dir / "in.0000.exr").string() +
                                  " --out " + fifo.string() + " --method ema",
                              &text),
            1)
      << text;
  EXPECT_NE(text.find("not a regular file"), std::string::npos) << text;
  struct stat st {};
  ASSERT_EQ(::stat(fifo.c_str(), &st), 0);
  EXPECT_TRUE(S_ISFIFO(st.st_mode)) << "the pipe was replaced";
}

}  // namespace
}  // namespace temporal
