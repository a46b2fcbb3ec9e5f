// Bad input loses nothing and is never accepted silently (issue 11): non-EXR files, truncated multi-part files,
// absurd headers, outputs that would replace inputs, frames of another size, temporary files of killed runs,
// unbounded patterns and frame numbers, non-finite parameters.
#include "temporal/io/atomic_file.h"
#include "temporal/io/exr.h"
#include "temporal/core/params.h"
#include "temporal/io/runner.h"
#include "temporal/core/sequence.h"

#include "test_support.h"

#include <gtest/gtest.h>

#include <sys/wait.h>
#include <unistd.h>

#include <cmath>
#include <csignal>
#include <fstream>
#include <limits>
#include <optional>

namespace {

using namespace temporal;
namespace fs = std::filesystem;

std::string read_bytes(const fs::path& p) {
  std::ifstream in(p, std::ios::binary);
  return {std::istreambuf_iterator<char>(in), {}};
}
void write_bytes(const fs::path& p, const std::string& bytes) { std::ofstream(p, std::ios::binary) << bytes; }

// A multi-part frame: colour plus two data layers.
Image frame(int w, int h, float v) {
  Image img = test::make_image(w, h, {"R", "G", "B", "motion.X", "motion.Y", "depth.Z"}, v);
  return img;
}

TEST(Robustness, ImagesOfAnotherFormatAreRefusedWithAHint) {
  const auto dir = test::scratch_dir("robust-format");
  write_bytes(dir / "a.png", std::string("\x89PNG\r\n\x1a\n", 8) + std::string(100, '\0'));
  auto r = read_exr((dir / "a.png").string());
  ASSERT_FALSE(r);
  EXPECT_EQ(r.error().kind, ErrorKind::Input);
  EXPECT_NE(r.error().message.find("PNG"), std::string::npos) << r.error().message;
  EXPECT_NE(r.error().message.find("oiiotool"), std::string::npos);
  write_bytes(dir / "b.exr", "");
  EXPECT_FALSE(read_exr((dir / "b.exr").string()));
  fs::create_directories(dir / "folder.exr");
  auto f = read_exr((dir / "folder.exr").string());
  ASSERT_FALSE(f);
  EXPECT_NE(f.error().message.find("folder"), std::string::npos);
  // Outputs must be named .exr: never EXR bytes under another extension.
  const Status s = write_exr((dir / "out.png").string(), frame(4, 4, 1.0f));
  ASSERT_FALSE(s);
  EXPECT_EQ(s.error().kind, ErrorKind::Usage);
  EXPECT_FALSE(fs::exists(dir / "out.png"));
}

TEST(Robustness, AFileTruncatedInAPartThatIsNotReadIsRefused) {
  const auto dir = test::scratch_dir("robust-truncated");
  const fs::path whole = dir / "whole.exr", cut = dir / "cut.exr";
  ASSERT_TRUE(write_exr(whole.string(), frame(64, 64, 0.5f)));
  const std::string bytes = read_bytes(whole);
  write_bytes(cut, bytes.substr(0, bytes.size() - 40));  // the last part (a data layer) loses its end
  ASSERT_TRUE(read_exr(whole.string(), ExrSelection{{"rgb"}}));
  auto r = read_exr(cut.string(), ExrSelection{{"rgb"}});  // only the colour part, which is intact
  ASSERT_FALSE(r);
  EXPECT_NE(r.error().message.find("truncated"), std::string::npos) << r.error().message;
  EXPECT_FALSE(read_exr_info(cut.string()));
}

TEST(Robustness, AnAbsurdHeaderSizeIsRefusedBeforeAnyAllocation) {
  const auto dir = test::scratch_dir("robust-huge");
  const fs::path p = dir / "huge.exr";
  ASSERT_TRUE(write_exr(p.string(), test::make_image(8, 8, {"R", "G", "B"}, 1.0f)));
  std::string bytes = read_bytes(p);
  // Rewrite the dataWindow box2i (xMin, yMin, xMax, yMax) of the header to 0, 0, 99999, 99999.
  const std::string key = std::string("dataWindow\0box2i\0", 17);
  const auto at = bytes.find(key);
  ASSERT_NE(at, std::string::npos);
  const std::size_t values = at + key.size() + 4;  // after the attribute's size field
  const std::int32_t box[4] = {0, 0, 99999, 99999};
  bytes.replace(values, 16, reinterpret_cast<const char*>(box), 16);
  write_bytes(p, bytes);
  auto r = read_exr(p.string());
  ASSERT_FALSE(r);
  EXPECT_EQ(r.error().kind, ErrorKind::Input);
  EXPECT_NE(r.error().message.find("100000x100000"), std::string::npos) << r.error().message;
}

// Found by tests/fuzz/exr_fuzz: a string attribute whose declared size runs past the end of the file made
// OpenEXR's C++ reader allocate that size (1.8 GB for a 12 kB file). Refused from the header walk, for a
// single-part and a multi-part file, before OpenEXR reads the value.
TEST(Robustness, AnAttributeLargerThanTheFileIsRefusedBeforeAnyAllocation) {
  const auto dir = test::scratch_dir("robust-attribute");
  for (const bool multipart : {false, true}) {
    const fs::path p = dir / (multipart ? "multi.exr" : "single.exr");
    Image img = multipart ? frame(8, 8, 1.0f) : test::make_image(8, 8, {"R", "G", "B"}, 1.0f);
    img.metadata().tool = "robustness-test 1.0";
    ASSERT_TRUE(write_exr(p.string(), img));
    std::string bytes = read_bytes(p);
    const std::string key = std::string("temporal:tool\0string\0", 21);
    const auto at = bytes.find(key);
    ASSERT_NE(at, std::string::npos) << multipart;
    const std::int32_t huge = 1851877396;  // the fuzzer's value
    bytes.replace(at + key.size(), 4, reinterpret_cast<const char*>(&huge), 4);
    write_bytes(p, bytes);
    for (const bool info : {false, true}) {
      const Error e = info ? read_exr_info(p.string()).error() : read_exr(p.string()).error();
      EXPECT_EQ(e.kind, ErrorKind::Input);
      EXPECT_NE(e.message.find("'temporal:tool' declares 1851877396 bytes"), std::string::npos) << e.message;
    }
  }
}

TEST(Robustness, PatternsAndFrameNumbersAreBounded) {
  auto a = SequencePattern::parse("out/run#3/color.####.exr");  // '#' in a folder name is not a placeholder
  ASSERT_TRUE(a);
  EXPECT_EQ(a->path(7), "out/run#3/color.0007.exr");
  auto b = SequencePattern::parse("x.%1000000d.exr");
  ASSERT_FALSE(b);
  EXPECT_LT(b.error().message.size(), 400u);
  EXPECT_FALSE(SequencePattern::parse("x.###########.exr"));
  auto neg = FrameRange::parse("-1");
  ASSERT_FALSE(neg);
  EXPECT_EQ(neg.error().kind, ErrorKind::Usage);
  auto huge = FrameRange::parse("2147483647-2147483647");
  ASSERT_FALSE(huge);
  EXPECT_EQ(huge.error().kind, ErrorKind::Usage);
  EXPECT_TRUE(FrameRange::parse("0-99999999"));
}

TEST(Robustness, NonFiniteAndOutOfRangeParametersAreUsageErrors) {
  float f = std::nanf("");
  Param p = Param::real("--alpha", "weight", &f, 0.0, 1.0);
  Status s = check_param(p);
  ASSERT_FALSE(s);
  EXPECT_EQ(s.error().kind, ErrorKind::Usage);
  f = INFINITY;
  EXPECT_FALSE(check_param(p));
  f = 1.5f;
  s = check_param(p);
  ASSERT_FALSE(s);
  EXPECT_NE(s.error().message.find("[0, 1]"), std::string::npos) << s.error().message;
  f = 0.5f;
  EXPECT_TRUE(check_param(p));
  float g = 0.0f;
  Param q = Param::positive("--scale", "scale", &g);
  EXPECT_FALSE(check_param(q));  // > 0
  EXPECT_EQ(param_range_text(q), "> 0");
}

// Issue 26 item 13: every floating-point option has a finite range; an "off / derived" 0 outside it is allowed by
// or_zero (morph-120hz --ppd: 0 or [0.01, 10000], so 1e-40 no longer makes fps / ppd infinite). The tools refuse to
// start with a floating-point Param whose range is not finite (has_finite_range).
TEST(Robustness, FloatParametersHaveFiniteRangesAndZeroCanBeTheOffValue) {
  float ppd = 0.0f;
  const Param p = Param::real_or_zero("--ppd", "pixels per degree", &ppd, 0.01, 1e4);
  EXPECT_TRUE(check_param(p));
  EXPECT_EQ(param_range_text(p), "0 or [0.01, 10000]");
  for (float bad : {1e-40f, 0.001f, -1.0f, 2e4f}) {
    ppd = bad;
    const Status s = check_param(p);
    ASSERT_FALSE(s) << bad;
    EXPECT_NE(s.error().message.find("it must be 0 or [0.01, 10000]"), std::string::npos) << s.error().message;
  }
  ppd = 0.01f;
  EXPECT_TRUE(check_param(p));
  EXPECT_TRUE(has_finite_range(p));
  float x = 0.0f;
  double d = 1.0;
  std::optional<double> o;
  int i = 0;
  EXPECT_FALSE(has_finite_range(Param::positive("--scale", "scale", &x)));
  EXPECT_FALSE(has_finite_range(Param::real("--a", "a", &x, 0.0, INFINITY)));
  EXPECT_FALSE(has_finite_range(Param::optional("--t", "threshold", &o)));
  EXPECT_TRUE(has_finite_range(Param::optional("--t", "threshold", &o, -1e6, 1e6)));
  EXPECT_TRUE(has_finite_range(Param::real("--d", "d", &d, 1.0, 1000.0)));
  EXPECT_TRUE(has_finite_range(Param::integer("--n", "n", &i, 0, std::numeric_limits<int>::max())));
}

// Issue 26: an empty value is a usage error naming the parameter, for text parameters too (it used to be kept as
// an empty string, and a number's empty value is refused as before).
TEST(Robustness, EmptyParameterValuesAreUsageErrors) {
  float f = 0.5f;
  std::string t = "keep";
  const ParamList params = {Param::real("--alpha", "weight", &f, 0.0, 1.0), Param::text("--name", "a name", &t)};
  for (const char* flag : {"--alpha", "--name"}) {
    Status s = apply_args(params, {flag, ""});
    ASSERT_FALSE(s) << flag;
    EXPECT_EQ(s.error().kind, ErrorKind::Usage);
    EXPECT_NE(s.error().message.find(std::string(flag) + " needs a value, got an empty one"), std::string::npos)
        << s.error().message;
  }
  EXPECT_EQ(f, 0.5f);
  EXPECT_EQ(t, "keep");
  EXPECT_TRUE(apply_args(params, {"--name", "x", "--alpha", "0.25"}));
  EXPECT_EQ(t, "x");
  EXPECT_EQ(f, 0.25f);
}

TEST(Robustness, StaleTemporaryFilesOfDeadProcessesAreRemoved) {
  const auto dir = test::scratch_dir("robust-stale");
  // A process that has ended: its PID is free (the child below), so its temporary file is stale.
  const pid_t child = fork();
  if (child == 0) _exit(0);
  int status = 0;
  waitpid(child, &status, 0);
  const fs::path stale = dir / (".out.exr.tmp" + std::to_string(child) + ".exr");
  const fs::path mine_alive = dir / (".out.exr.tmp" + std::to_string(getppid()) + ".exr");  // a live process
  write_bytes(stale, "partial");
  write_bytes(mine_alive, "partial");
  ASSERT_TRUE(write_exr((dir / "out.exr").string(), frame(4, 4, 1.0f)));
  EXPECT_FALSE(fs::exists(stale));
  EXPECT_TRUE(fs::exists(mine_alive));
  EXPECT_TRUE(fs::exists(dir / "out.exr"));
}

TEST(Robustness, ASignalRemovesTheTemporaryFilesBeingWritten) {
  const auto dir = test::scratch_dir("robust-signal");
  const pid_t child = fork();
  if (child == 0) {
    TemporaryFile tmp((dir / "x.exr").string());
    write_bytes(tmp.path(), "half written");
    std::signal(SIGTERM, [](int sig) {
      remove_temporary_files();
      std::signal(sig, SIG_DFL);
      std::raise(sig);
    });
    std::raise(SIGTERM);
    _exit(3);  // not reached
  }
  int status = 0;
  waitpid(child, &status, 0);
  EXPECT_TRUE(WIFSIGNALED(status));
  std::size_t left = 0;
  for (const auto& e : fs::directory_iterator(dir)) left += e.path().filename().string().find(".tmp") != std::string::npos;
  EXPECT_EQ(left, 0u);
}

// A stage that copies its input (to drive the runner).
class CopyStage final : public FrameStage {
 public:
  CopyStage() { inputs_.input_layers = {"rgb"}; }
  const StageInputs& inputs() const override { return inputs_; }
  Status process(const StageFrame& f, std::vector<StageOutput>& out) override {
    copy_ = *f.input;
    StageOutput o;
    o.frame = f.frame;
    o.image = &copy_;
    out.push_back(o);
    return Status::ok();
  }

 private:
  StageInputs inputs_;
  Image copy_;
};

TEST(Robustness, TheRunnerNeverWritesOverItsInputs) {
  const auto dir = test::scratch_dir("robust-overwrite");
  for (int f = 0; f < 3; ++f)
    ASSERT_TRUE(write_exr((dir / ("c." + std::to_string(f) + ".exr")).string(), frame(8, 8, float(f))));
  const std::string before = read_bytes(dir / "c.1.exr");
  CopyStage stage;
  SequenceOptions o;
  o.input = (dir / "c.%d.exr").string();
  for (const std::string& out : {o.input, (dir / "." / "c.%d.exr").string(), (dir / "c.%1d.exr").string()}) {
    o.out = out;
    auto r = run_sequence(o, stage, {"test", ""});
    ASSERT_FALSE(r) << out;
    EXPECT_EQ(r.error().kind, ErrorKind::Usage);
    EXPECT_NE(r.error().message.find("one of this run's inputs"), std::string::npos) << r.error().message;
  }
  fs::create_symlink(dir / "c.2.exr", dir / "o.1.exr");  // output frame 1 is a link to input frame 2
  o.out = (dir / "o.%d.exr").string();
  EXPECT_FALSE(run_sequence(o, stage, {"test", ""}));
  EXPECT_EQ(read_bytes(dir / "c.1.exr"), before);
  EXPECT_TRUE(read_exr((dir / "c.2.exr").string()));
  o.out = (dir / "out.%d.png").string();
  EXPECT_FALSE(run_sequence(o, stage, {"test", ""}));
  EXPECT_FALSE(fs::exists(dir / "out.0.png"));
}

// Issue 26 item 10: an input that cannot be examined (a symbolic link loop as a colour or G-buffer frame, in a
// range, as a single file, or read directly) is an Input error naming it, never a std::filesystem exception (which
// the tools report as an internal error, exit 5).
TEST(Robustness, InputsThatCannotBeExaminedAreInputErrors) {
  const auto dir = test::scratch_dir("robust-link-loop");
  for (int f = 0; f < 3; ++f)
    ASSERT_TRUE(write_exr((dir / ("c." + std::to_string(f) + ".exr")).string(), frame(8, 8, float(f))));
  ASSERT_TRUE(write_exr((dir / "g.0.exr").string(), frame(8, 8, 0.0f)));
  fs::create_symlink("g.1.exr", dir / "g.1.exr");  // a link to itself: ELOOP
  ASSERT_TRUE(write_exr((dir / "g.2.exr").string(), frame(8, 8, 0.0f)));
  auto loop_error = [&](const Error& e, const std::string& file) {
    EXPECT_EQ(e.kind, ErrorKind::Input) << e.message;
    EXPECT_NE(e.file.find(file), std::string::npos) << e.file;
    EXPECT_NE(e.message.find("cannot be examined"), std::string::npos) << e.message;
  };
  auto pattern = SequencePattern::parse((dir / "g.%d.exr").string());
  ASSERT_TRUE(pattern);
  auto frames = resolve_frames(*pattern, FrameRange{0, 2});
  ASSERT_FALSE(frames);
  loop_error(frames.error(), "g.1.exr");
  auto single = SequencePattern::parse((dir / "g.1.exr").string());
  ASSERT_TRUE(single);
  auto one = resolve_frames(*single, std::nullopt);
  ASSERT_FALSE(one);
  loop_error(one.error(), "g.1.exr");
  auto read = read_exr((dir / "g.1.exr").string());
  ASSERT_FALSE(read);
  loop_error(read.error(), "g.1.exr");
  // Through the runner, the input's frame 1 being the loop: with --frames it is found before any work, without
  // (frames found on disk) when frame 1 is read.
  CopyStage stage;
  SequenceOptions o;
  o.input = pattern->pattern();
  o.out = (dir / "o.%d.exr").string();
  o.frames = "0-2";
  auto r = run_sequence(o, stage, {"test", ""});
  ASSERT_FALSE(r);
  loop_error(r.error(), "g.1.exr");
  EXPECT_FALSE(fs::exists(dir / "o.0.exr"));
  o.frames.clear();
  r = run_sequence(o, stage, {"test", ""});
  ASSERT_FALSE(r);
  loop_error(r.error(), "g.1.exr");
}

TEST(Robustness, AFrameOfAnotherSizeStopsTheRun) {
  const auto dir = test::scratch_dir("robust-size");
  ASSERT_TRUE(write_exr((dir / "c.0.exr").string(), frame(8, 8, 0.0f)));
  ASSERT_TRUE(write_exr((dir / "c.1.exr").string(), frame(8, 6, 0.0f)));
  CopyStage stage;
  SequenceOptions o;
  o.input = (dir / "c.%d.exr").string();
  o.out = (dir / "o.%d.exr").string();
  auto r = run_sequence(o, stage, {"test", ""});
  ASSERT_FALSE(r);
  EXPECT_EQ(r.error().kind, ErrorKind::Input);
  EXPECT_NE(r.error().message.find("one size"), std::string::npos) << r.error().message;
}

}  // namespace
