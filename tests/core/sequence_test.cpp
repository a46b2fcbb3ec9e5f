#include "temporal/core/sequence.h"

#include "test_support.h"

#include <fstream>

namespace temporal {
namespace {

void touch(const std::filesystem::path& p) { std::ofstream(p) << "x"; }

TEST(FrameRange, Parses) {
  auto r = FrameRange::parse("3-10");
  ASSERT_TRUE(r);
  EXPECT_EQ(r->first, 3);
  EXPECT_EQ(r->last, 10);
  EXPECT_EQ(r->count(), 8);
  auto one = FrameRange::parse("7");
  ASSERT_TRUE(one);
  EXPECT_EQ(one->first, 7);
  EXPECT_EQ(one->last, 7);
  EXPECT_FALSE(FrameRange::parse("10-3"));
  EXPECT_FALSE(FrameRange::parse("a-b"));
  EXPECT_FALSE(FrameRange::parse("3-"));
  EXPECT_EQ(FrameRange::parse("x").error().kind, ErrorKind::Usage);
}

// oiiotool's frame lists: x N every Nth frame, y N all but every Nth (a 40 -> 120 Hz study's rendered and
// in-between frames).
TEST(FrameRange, EveryNthAndAllButEveryNth) {
  auto x = FrameRange::parse("0-10x3");
  ASSERT_TRUE(x);
  EXPECT_EQ(x->frames(), (std::vector<int>{0, 3, 6, 9}));
  EXPECT_EQ(x->count(), 4);
  auto y = FrameRange::parse("0-10y3");
  ASSERT_TRUE(y);
  EXPECT_EQ(y->frames(), (std::vector<int>{1, 2, 4, 5, 7, 8, 10}));
  EXPECT_EQ(y->count(), 7);
  EXPECT_TRUE(y->contains(5));
  EXPECT_FALSE(y->contains(6));
  EXPECT_FALSE(y->contains(11));
  auto x1 = FrameRange::parse("4-6x1");
  ASSERT_TRUE(x1);
  EXPECT_EQ(x1->frames(), (std::vector<int>{4, 5, 6}));
  EXPECT_EQ(FrameRange::parse("0-10x0").error().kind, ErrorKind::Usage);
  EXPECT_FALSE(FrameRange::parse("0-10y1"));  // selects no frame
  EXPECT_FALSE(FrameRange::parse("0-10x"));
  EXPECT_FALSE(FrameRange::parse("0-10z3"));
}

TEST(SequencePattern, HashesAndPrintf) {
  auto hashes = SequencePattern::parse("dir/gbuffer.####.exr");
  ASSERT_TRUE(hashes);
  EXPECT_EQ(hashes->path(12), "dir/gbuffer.0012.exr");
  EXPECT_EQ(hashes->path(12345), "dir/gbuffer.12345.exr");
  auto printf_style = SequencePattern::parse("a.%04d.exr");
  ASSERT_TRUE(printf_style);
  EXPECT_EQ(printf_style->path(7), "a.0007.exr");
  auto unpadded = SequencePattern::parse("a.%d.exr");
  ASSERT_TRUE(unpadded);
  EXPECT_EQ(unpadded->path(7), "a.7.exr");
  auto single = SequencePattern::parse("still.exr");
  ASSERT_TRUE(single);
  EXPECT_FALSE(single->has_placeholder());
  EXPECT_EQ(single->path(3), "still.exr");
  EXPECT_FALSE(SequencePattern::parse("a.##.b.##.exr"));
  EXPECT_FALSE(SequencePattern::parse("a.%s.exr"));
}

TEST(SequencePattern, FindsFramesAndReportsGaps) {
  const auto dir = test::scratch_dir("sequence_gaps");
  for (int f : {3, 4, 5}) touch(dir / ("c." + std::string(f < 10 ? "000" : "00") + std::to_string(f) + ".exr"));
  touch(dir / "other.0001.exr");
  touch(dir / ".c.0006.exr.tmp123.exr");  // an unfinished atomic write is never a frame
  auto pattern = SequencePattern::parse((dir / "c.####.exr").string());
  ASSERT_TRUE(pattern);
  auto all = resolve_frames(*pattern, std::nullopt);
  ASSERT_TRUE(all) << all.error().message;
  EXPECT_EQ(*all, (std::vector<int>{3, 4, 5}));
  auto some = resolve_frames(*pattern, FrameRange{4, 5});
  ASSERT_TRUE(some);
  EXPECT_EQ(*some, (std::vector<int>{4, 5}));
  auto missing = resolve_frames(*pattern, FrameRange{4, 6});
  ASSERT_FALSE(missing);
  EXPECT_EQ(missing.error().kind, ErrorKind::Input);
  EXPECT_NE(missing.error().file.find("c.0006.exr"), std::string::npos);

  touch(dir / "c.0008.exr");
  auto gap = resolve_frames(*pattern, std::nullopt);
  ASSERT_FALSE(gap);
  EXPECT_NE(gap.error().file.find("c.0006.exr"), std::string::npos) << gap.error().file;
  EXPECT_NE(gap.error().message.find("gap"), std::string::npos);

  auto empty = SequencePattern::parse((dir / "none.####.exr").string());
  auto nothing = resolve_frames(*empty, std::nullopt);
  ASSERT_FALSE(nothing);
  EXPECT_NE(nothing.error().message.find("no frames"), std::string::npos);
}

TEST(FrameList, ParsesItemsAndRanges) {
  auto list = parse_frame_list("10, 2-4,3");
  ASSERT_TRUE(list);
  EXPECT_EQ(*list, (std::vector<int>{2, 3, 4, 10}));
  EXPECT_FALSE(parse_frame_list("1,x"));
  auto empty = parse_frame_list("");
  ASSERT_TRUE(empty);
  EXPECT_TRUE(empty->empty());
}

}  // namespace
}  // namespace temporal
