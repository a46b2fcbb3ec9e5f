// Resumable state (--state-in / --state-out): for every method and named variant, a run interrupted after a few
// frames and resumed from its saved state (written to an EXR file and read back, as the tool does) gives the same
// bits as the uninterrupted run; states of another method, other options or another size are refused with a
// message that says what differs, and damaged ones (NaN or infinity in a plane) are refused or kept out of the
// output.
#include "synthetic.h"

#include "temporal/io/exr.h"
#include "temporal/upsample/methods.h"
#include "temporal/upsample/upsample.h"

#include <gtest/gtest.h>
#include <test_support.h>

#include <cmath>
#include <cstring>
#include <filesystem>
#include <limits>

namespace up = temporal::upsample;
using temporal::Image;
using temporal::test::make_frame;
using temporal::test::SyntheticScene;

namespace {

const std::vector<std::string> kRGB = {"R", "G", "B"};

// A pan with a moving square: every history path (aligned and gathered taps, disocclusions) is exercised.
SyntheticScene scene() {
  SyntheticScene s;
  s.camera_velocity = {0.75f, -0.5f};
  s.object = true;
  s.object_velocity = {1.5f, 1.0f};
  return s;
}

up::Options options(const up::MethodVariant& v) {
  std::vector<std::string> args = v.args;
  args.push_back("--debug-layers");  // the debug layers show every per-pixel state (w_f, h_w, convergence)
  return *up::make_options(v.method, args);
}

// Number of float values that differ in their bits between two images with the same channels.
std::size_t differing_bits(const Image& a, const Image& b) {
  std::size_t n = 0;
  EXPECT_EQ(a.channel_names(), b.channel_names());
  for (const auto& c : a.channel_names()) {
    const float* pa = a.plane(c);
    const float* pb = b.plane(c);
    if (!pa || !pb) continue;
    for (std::size_t i = 0; i < a.pixel_count(); ++i) n += std::memcmp(&pa[i], &pb[i], sizeof(float)) != 0;
  }
  return n;
}

// The state after `frames` frames, written to an EXR file and read back.
Image saved_state(const up::Options& o, int frames, const std::string& name) {
  up::Upsampler u(o);
  for (int t = 0; t < frames; ++t) {
    const auto f = make_frame(scene(), t);
    EXPECT_TRUE(u.process(f.gbuffer, f.low, kRGB, false).has_value());
  }
  auto state = u.save_state();
  EXPECT_TRUE(state.has_value()) << (state ? "" : state.error().message);
  const std::string path = (temporal::test::scratch_dir("upsample_state") / (name + ".exr")).string();
  EXPECT_TRUE(temporal::write_exr(path, *state));
  auto back = temporal::read_exr(path);
  EXPECT_TRUE(back.has_value());
  return back ? *back : Image();
}

}  // namespace

TEST(UpsampleState, ResumedRunIsBitIdentical) {
  const int split = 5, frames = 12;  // split inside the first pattern cycle, end in the second
  for (const up::MethodVariant& v : up::method_variants()) {
    if (!up::find_entry(v.method)->info.has_state) continue;
    const up::Options o = options(v);
    up::Upsampler whole(o);
    std::vector<Image> expected;
    for (int t = 0; t < frames; ++t) {
      const auto f = make_frame(scene(), t);
      auto r = whole.process(f.gbuffer, f.low, kRGB, false);
      ASSERT_TRUE(r.has_value()) << v.name << ": " << r.error().message;
      expected.push_back(**r);
    }
    up::Upsampler resumed(o);
    ASSERT_TRUE(resumed.load_state(saved_state(o, split, v.name))) << v.name;
    for (int t = split; t < frames; ++t) {
      const auto f = make_frame(scene(), t);
      up::FrameStats stats;
      auto r = resumed.process(f.gbuffer, f.low, kRGB, false, &stats);
      ASSERT_TRUE(r.has_value()) << v.name << ": " << r.error().message;
      EXPECT_FALSE(stats.history_reset) << v.name;
      EXPECT_EQ(differing_bits(**r, expected[std::size_t(t)]), 0u) << v.name << " frame " << t;
    }
    // Control: a run that starts at `split` without the state differs (the test can fail).
    up::Upsampler fresh(o);
    const auto f = make_frame(scene(), split);
    auto r = fresh.process(f.gbuffer, f.low, kRGB, false);
    ASSERT_TRUE(r.has_value());
    EXPECT_GT(differing_bits(**r, expected[split]), 100u) << v.name;
  }
}

TEST(UpsampleState, SpatialHasNoState) {
  up::Upsampler u(*up::make_options("spatial"));
  EXPECT_FALSE(u.has_state());
  const auto f = make_frame(scene(), 0);
  ASSERT_TRUE(u.process(f.gbuffer, f.low, kRGB, false).has_value());
  auto s = u.save_state();
  ASSERT_FALSE(s.has_value());
  EXPECT_EQ(s.error().kind, temporal::ErrorKind::Usage);
  EXPECT_NE(s.error().message.find("keeps no state"), std::string::npos) << s.error().message;
}

TEST(UpsampleState, RefusesAnotherMethodOptionsOrSize) {
  const Image herzog = saved_state(*up::make_options("herzog"), 3, "refuse_herzog");
  {  // another method
    up::Upsampler u(*up::make_options("temporal"));
    const temporal::Status s = u.load_state(herzog);
    ASSERT_FALSE(s);
    EXPECT_EQ(s.error().kind, temporal::ErrorKind::Usage);
    EXPECT_NE(s.error().message.find("--method herzog"), std::string::npos) << s.error().message;
  }
  {  // options that shape the state: the gradient grid
    up::Upsampler u(*up::make_options("herzog", {"--gradient-scale", "4"}));
    const temporal::Status s = u.load_state(herzog);
    ASSERT_FALSE(s);
    EXPECT_NE(s.error().message.find("gradient-scale"), std::string::npos) << s.error().message;
  }
  {  // drobot's two modes keep different buffers
    const Image cache = saved_state(*up::make_options("drobot"), 3, "refuse_drobot");
    up::Upsampler u(*up::make_options("drobot", {"--mode", "refresh"}));
    const temporal::Status s = u.load_state(cache);
    ASSERT_FALSE(s);
    EXPECT_NE(s.error().message.find("mode"), std::string::npos) << s.error().message;
  }
  {  // another frame size: refused at the first frame, naming --state-in
    up::Upsampler u(*up::make_options("herzog"));
    ASSERT_TRUE(u.load_state(herzog));
    SyntheticScene other = scene();
    other.width = 32;
    const auto f = make_frame(other, 3);
    auto r = u.process(f.gbuffer, f.low, kRGB, false, nullptr, {"g.exr", "s.exr"});
    ASSERT_FALSE(r.has_value());
    EXPECT_EQ(r.error().kind, temporal::ErrorKind::Input);
    EXPECT_NE(r.error().message.find("--state-in"), std::string::npos) << r.error().message;
  }
  {  // not a state at all
    up::Upsampler u(*up::make_options("herzog"));
    const temporal::Status s = u.load_state(make_frame(scene(), 0).low);
    ASSERT_FALSE(s);
    EXPECT_NE(s.error().message.find("not an upsample-st state"), std::string::npos) << s.error().message;
  }
}

// A damaged state (NaN or infinity in some of its values) loses nothing downstream: for every method and variant and
// every channel of its state, a resumed run either refuses the state with an Input error that names the channel
// (the histories' and drobot's cache's payload and frame counts, which every --state-out writes finite) or keeps its
// outputs finite for three frames (the other planes: herzog's and taau's weights, gradients and locks, the previous
// depth, which their history tests reject). Before the check, temporal's, drobot's and drobot-refresh's outputs
// took the NaN: 755 to 24156 values in three frames.
TEST(UpsampleState, DamagedStateIsRefusedOrNeverReachesTheOutput) {
  for (const up::MethodVariant& v : up::method_variants()) {
    if (!up::find_entry(v.method)->info.has_state) continue;
    const up::Options o = *up::make_options(v.method, v.args);
    const Image good = saved_state(o, 5, v.name + "_damaged");
    for (const auto& c : good.channel_names()) {
      if (!good.plane(c)) continue;  // the ids (uint planes)
      const bool payload = c.rfind("history.", 0) == 0 || c.rfind("cache.", 0) == 0;
      const bool must_refuse = (payload && c != "history.weight" && c != "cache.depth");
      Image bad = good;
      float* p = bad.plane(c);
      for (std::size_t i = 0; i < bad.pixel_count(); i += 97)
        p[i] = i % 2 ? std::numeric_limits<float>::quiet_NaN() : std::numeric_limits<float>::infinity();
      up::Upsampler u(o);
      ASSERT_TRUE(u.load_state(bad)) << v.name << " " << c;  // checked when the first frame needs it
      std::size_t non_finite = 0;
      bool refused = false;
      for (int t = 5; t < 8; ++t) {
        const auto f = make_frame(scene(), t);
        auto r = u.process(f.gbuffer, f.low, kRGB, false);
        if (!r) {
          refused = true;
          EXPECT_EQ(t, 5) << v.name << " " << c;
          EXPECT_EQ(r.error().kind, temporal::ErrorKind::Input) << v.name << " " << c;
          EXPECT_NE(r.error().message.find("'" + c + "'"), std::string::npos) << r.error().message;
          EXPECT_NE(r.error().message.find("not finite"), std::string::npos) << r.error().message;
          break;
        }
        for (const auto& ch : kRGB)
          for (std::size_t i = 0; i < (*r)->pixel_count(); ++i) non_finite += !std::isfinite((*r)->plane(ch)[i]);
      }
      EXPECT_EQ(refused, must_refuse) << v.name << " " << c;
      EXPECT_EQ(non_finite, 0u) << v.name << " " << c;
    }
  }
}
