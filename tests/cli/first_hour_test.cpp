// Issue 25 ("A new user's first hour"), items 5 and 6: the silent surprises and the unhelpful messages a new user
// met, each run through the built tools as that user ran them.
#include "temporal/io/exr.h"

#include "test_support.h"

#include <gtest/gtest.h>

#include <cstdio>
#include <filesystem>
#include <string>

namespace temporal {
namespace {

namespace fs = std::filesystem;

std::string tool(const std::string& name) { return test::tool_path(name).string(); }

// Frames first..last of a small moving edge at 40 fps, named NAME.####.exr, each stamped with its frame and time
// as render-gbuffer stamps them (`stamp` false: no temporal:frame / time, as a third-party renderer may write).
void write_frames(const fs::path& dir, const std::string& name, int first, int last, bool stamp = true) {
  for (int f = first; f <= last; ++f) {
    Image img = test::make_image(32, 24, {"R", "G", "B"}, 0.2f);
    for (const char* c : {"R", "G", "B"})
      for (int y = 0; y < 24; ++y)
        for (int x = 4 + 3 * f; x < 8 + 3 * f && x < 32; ++x) img.plane(c)[std::size_t(y) * 32 + std::size_t(x)] = 0.9f;
    if (stamp) {
      img.metadata().frame = f;
      img.metadata().fps = 40.0;
      img.metadata().time = f / 40.0;
    }
    char file[64];
    std::snprintf(file, sizeof file, "%s.%04d.exr", name.c_str(), f);
    ASSERT_TRUE(write_exr((dir / file).string(), img));
  }
}

// `filter-phlm --input color.0003.exr --out a.####.exr` wrote a.0000.exr with `temporal:frame 0` beside frame 3's
// time. The output now takes the input's own frame; a file without temporal:frame into a pattern is refused.
TEST(FirstHour, OneFileIntoAPatternKeepsTheFilesFrame) {
  const fs::path dir = test::scratch_dir("first-hour-plain-file");
  write_frames(dir, "color", 3, 3);
  std::string out;
  ASSERT_EQ(test::run_command("cd " + dir.string() + " && " + tool("filter-phlm") +
                                  " --input color.0003.exr --out a.####.exr --method fxaa",
                              &out),
            0)
      << out;
  EXPECT_FALSE(fs::exists(dir / "a.0000.exr"));
  ASSERT_TRUE(fs::exists(dir / "a.0003.exr")) << out;
  auto info = read_exr_info((dir / "a.0003.exr").string());
  ASSERT_TRUE(info) << info.error().message;
  EXPECT_EQ(info->metadata.frame.value_or(-1), 3);
  EXPECT_NEAR(info->metadata.time.value_or(-1.0), 3 / 40.0, 1e-6);  // stored as a float
  // --frames still names the frame when the header has none.
  write_frames(dir, "plain", 5, 5, false);
  EXPECT_EQ(test::run_command("cd " + dir.string() + " && " + tool("filter-phlm") +
                                  " --input plain.0005.exr --out b.####.exr --method fxaa",
                              &out),
            1)
      << out;
  EXPECT_NE(out.find("without a temporal:frame attribute"), std::string::npos) << out;
  EXPECT_NE(out.find("--frames N"), std::string::npos) << out;
  EXPECT_FALSE(fs::exists(dir / "b.0000.exr"));
  ASSERT_EQ(test::run_command("cd " + dir.string() + " && " + tool("filter-phlm") +
                                  " --input plain.0005.exr --frames 5 --out b.####.exr --method fxaa",
                              &out),
            0)
      << out;
  EXPECT_TRUE(fs::exists(dir / "b.0005.exr"));
}

// `filter-phlm --method taa` without --gbuffer took the scene as static and said nothing. Every method that reads
// motion now warns once (through the runner, so upsample-st and morph-120hz would too); one that reads none
// (fxaa) does not.
TEST(FirstHour, AMethodThatReadsMotionWarnsWithoutAGBuffer) {
  const fs::path dir = test::scratch_dir("first-hour-no-motion");
  write_frames(dir, "color", 0, 3);
  for (const std::string method : {"taa", "phlm", "fxaa"}) {
    std::string out;
    const std::string cmd = "cd " + dir.string() + " && " + tool("filter-phlm") + " --input color.####.exr --out " +
                            method + ".####.exr --method " + method;
    ASSERT_EQ(test::run_command(cmd, &out), 0) << method << "\n" << out;
    const bool warned = out.find("warning: no --gbuffer: this method reads motion vectors") != std::string::npos;
    EXPECT_EQ(warned, method != "fxaa") << method << "\n" << out;
    EXPECT_EQ(out.find("no --gbuffer") == out.rfind("no --gbuffer"), true) << "warned more than once\n" << out;
  }
}

// An output folder that does not exist is created for the outputs, and every tool now says so on stderr (once
// per folder); an existing folder gets no note.
TEST(FirstHour, EveryToolSaysWhenItCreatesAnOutputFolder) {
  const fs::path dir = test::scratch_dir("first-hour-new-folder");
  write_frames(dir, "color", 0, 1);
  std::string out;
  const std::string cd = "cd " + dir.string() + " && ";
  ASSERT_EQ(test::run_command(cd + tool("filter-phlm") + " --input color.####.exr --out new/f/a.####.exr --method fxaa",
                              &out),
            0)
      << out;
  EXPECT_NE(out.find("filter-phlm: new/f: note: the folder does not exist; it will be created"), std::string::npos)
      << out;
  EXPECT_TRUE(fs::exists(dir / "new/f/a.0001.exr"));
  ASSERT_EQ(test::run_command(cd + tool("filter-phlm") + " --input color.####.exr --out new/f/a.####.exr --method fxaa",
                              &out),
            0)
      << out;
  EXPECT_EQ(out.find("note:"), std::string::npos) << "the folder exists now\n" << out;
  ASSERT_EQ(test::run_command(cd + tool("morph-120hz") + " --input color.####.exr --fps 40 --method repeat --out "
                                   "m/r.####.exr",
                              &out),
            0)
      << out;
  EXPECT_NE(out.find("morph-120hz: m: note: the folder does not exist"), std::string::npos) << out;
  // compare: files (--csv, --json) and folders (--error-maps), each folder named once.
  ASSERT_EQ(test::run_command(cd + tool("compare") + " --reference color.####.exr color.####.exr --csv c/m.csv "
                                   "--json c/m.json --error-maps maps",
                              &out),
            0)
      << out;
  EXPECT_NE(out.find("compare: c: note: the folder does not exist"), std::string::npos) << out;
  EXPECT_EQ(out.find("compare: c: note:"), out.rfind("compare: c: note:")) << out;
  EXPECT_NE(out.find("compare: maps: note: the folder does not exist"), std::string::npos) << out;
  EXPECT_TRUE(fs::exists(dir / "c/m.csv") && fs::exists(dir / "maps"));
  // render-gbuffer's --out is a folder.
  ASSERT_EQ(test::run_command(cd + tool("render-gbuffer") + " " +
                                  (test::source_dir() / "assets/scenes/walkers.glb").string() +
                                  " --size 32x24 --frames 0-0 --outputs gbuffer --out r/g",
                              &out),
            0)
      << out;
  EXPECT_NE(out.find("render-gbuffer: r/g: note: the folder does not exist"), std::string::npos) << out;
}

// Patterns: a lone '#' is refused with the convention it would have meant; `###` over 4-digit files says that
// they are there and how to name them; a colour file given as --gbuffer says it looks like colour and what
// --gbuffer takes (not --layer).
TEST(FirstHour, PatternAndGBufferMessagesSayWhatToDo) {
  const fs::path dir = test::scratch_dir("first-hour-messages");
  write_frames(dir, "color", 0, 2);
  std::string out;
  const std::string cd = "cd " + dir.string() + " && ";
  EXPECT_EQ(test::run_command(cd + tool("filter-phlm") + " --input color.#.exr --out a.####.exr --method fxaa", &out), 1)
      << out;
  EXPECT_NE(out.find("a lone '#' is one digit in Nuke but four in oiiotool"), std::string::npos) << out;
  EXPECT_EQ(test::run_command(cd + tool("compare") + " --reference color.###.exr color.####.exr", &out), 2) << out;
  EXPECT_NE(out.find("there is color.0000.exr, numbered with another width"), std::string::npos) << out;
  EXPECT_EQ(test::run_command(cd + tool("filter-phlm") + " --input color.###.exr --out a.####.exr --method fxaa", &out), 2)
      << out;
  EXPECT_NE(out.find("write one # per digit"), std::string::npos) << out;
  EXPECT_EQ(test::run_command(cd + tool("filter-phlm") +
                                  " --input color.####.exr --gbuffer color.####.exr --out t.####.exr --method taa",
                              &out),
            2)
      << out;
  EXPECT_NE(out.find("--gbuffer: this file has no motion layer (it has "), std::string::npos) << out;
  EXPECT_NE(out.find("it looks like a colour image"), std::string::npos) << out;
  EXPECT_EQ(out.find("--layer"), std::string::npos) << "--layer does not pick G-buffer layers\n" << out;
}

// Help texts list only the exit codes a tool returns: 3 (a failed threshold) is compare's alone.
TEST(FirstHour, HelpListsOnlyTheExitCodesTheToolReturns) {
  for (const std::string t : {"render-gbuffer", "upsample-st", "filter-phlm", "morph-120hz", "compare"}) {
    std::string out;
    ASSERT_EQ(test::run_command(tool(t) + " --help", &out), 0) << out;
    const auto codes = out.find("Exit codes:");
    ASSERT_NE(codes, std::string::npos) << t;
    const std::string line = out.substr(codes, out.find('\n', codes) - codes);
    EXPECT_EQ(line.find(" 3 ") != std::string::npos, t == "compare") << t << ": " << line;
  }
}

}  // namespace
}  // namespace temporal
