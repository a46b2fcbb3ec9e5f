// The per-frame context's contract with the methods' states (libtemporal/src/upsample/method.h): a state whose
// gathers_low_geometry() is true gathers the samples' geometry itself (low_geometry_row.inc) and must not read
// FrameContext's planes, which Upsampler::process leaves empty for it (clear_low_geometry).
#include "drobot_options.h"     // libtemporal/src/upsample (internal)
#include "method.h"             // libtemporal/src/upsample (internal)
#include "synthetic.h"
#include "upsample_context.h"   // tests/gpu: the FrameContext of a synthetic frame, as Upsampler builds it

#include <gtest/gtest.h>

#include <algorithm>
#include <cstring>
#include <limits>

namespace temporal::upsample {
namespace {

Options drobot_options_with_mode(const char* mode) {
  Options o;
  static_cast<OptionsOf<DrobotOptions>&>(*o.per_method.find("drobot")).mode = mode;
  return o;
}

std::unique_ptr<MethodState> cpu_drobot(const Options& o, const Geometry& g) {
  return find_implementation(*find_entry("drobot"), kCpuDevice)->make(o, g);
}

// A moving square over a panning background, k = 4, odd low-resolution sizes, with a NaN sample each frame (its
// validity must come from the state's own gather).
std::vector<test::SyntheticFrame> sequence(int n) {
  test::SyntheticScene scene;
  scene.width = 76;
  scene.height = 52;
  scene.camera_velocity = {0.6f, -0.4f};
  scene.object = true;
  scene.object_velocity = {1.5f, 0.7f};
  std::vector<test::SyntheticFrame> frames;
  for (int t = 0; t < n; ++t) {
    frames.push_back(test::make_frame(scene, t));
    frames.back().low.plane("G")[std::size_t((7 * t) % 200)] = std::numeric_limits<float>::quiet_NaN();
  }
  return frames;
}

bool same_bits(const Image& a, const Image& b, const std::string& channel) {
  const float *pa = a.plane(channel), *pb = b.plane(channel);
  return pa && pb && std::memcmp(pa, pb, sizeof(float) * std::size_t(a.width()) * a.height()) == 0;
}

// drobot's cache mode gives the same bits, frame after frame, with the framework's sample geometry, with those planes
// overwritten (a NaN depth and every sample valid: what a state that read them would get wrong) and with them empty
// (what Upsampler::process leaves it); refresh mode reads them and says so.
TEST(UpsampleFrameContext, DrobotCacheModeGathersItsOwnSampleGeometry) {
  const auto frames = sequence(6);
  const Geometry g = test::geometry_of(frames[0]);
  const Options cache = drobot_options_with_mode("cache");
  EXPECT_FALSE(cpu_drobot(drobot_options_with_mode("refresh"), g)->gathers_low_geometry());
  std::unique_ptr<MethodState> states[3] = {cpu_drobot(cache, g), cpu_drobot(cache, g), cpu_drobot(cache, g)};
  ASSERT_TRUE(states[0]->gathers_low_geometry());
  FrameContext f;
  for (std::size_t t = 0; t < frames.size(); ++t) {
    FrameStats stats[3];
    const Image* out[3];
    for (int i = 0; i < 3; ++i) {
      test::build_context(f, cache, frames[t], false, true);  // gathers the planes (gather_low_geometry)
      if (i == 1) {
        std::fill(f.lz.begin(), f.lz.end(), std::numeric_limits<float>::quiet_NaN());
        std::fill(f.lvalid.begin(), f.lvalid.end(), 1.0f);
      }
      if (i == 2) clear_low_geometry(f);
      out[i] = &states[i]->run(f, t > 0, stats[i]);
    }
    for (int i = 1; i < 3; ++i) {
      for (const char* c : {"R", "G", "B", "debug.confidence", "debug.convergence"})
        EXPECT_TRUE(same_bits(*out[0], *out[i], c)) << "frame " << t << ", run " << i << ", " << c;
      EXPECT_EQ(stats[0].history_pixels, stats[i].history_pixels) << t;
    }
  }
}

// TapTable::build keeps a table it already holds (the frame's tables repeat: the cache grid's never change, the
// samples' cycle through the jitter offsets) and rebuilds for any other (full, low, k, s): the entries are always those
// of a fresh table.
TEST(UpsampleFrameContext, TapTablesAreRebuiltOnlyForANewGrid) {
  auto same = [](const TapTable& a, const TapTable& b) {
    return a.i0 == b.i0 && a.i1 == b.i1 && a.d == b.d && a.v0 == b.v0 && a.v1 == b.v1;
  };
  TapTable t;
  EXPECT_TRUE(t.build(77, 20, 4, 1));
  EXPECT_FALSE(t.build(77, 20, 4, 1));
  const int keys[][4] = {{77, 20, 4, 3}, {77, 20, 4, 1}, {76, 20, 4, 1}, {77, 19, 4, 1}, {77, 26, 3, 1}, {9, 20, 4, 1}};
  for (const auto& key : keys) {
    EXPECT_TRUE(t.build(key[0], key[1], key[2], key[3]));
    TapTable fresh;
    fresh.build(key[0], key[1], key[2], key[3]);
    EXPECT_TRUE(same(t, fresh)) << key[0] << " " << key[1] << " " << key[2] << " " << key[3];
    EXPECT_EQ(t.i0.size(), std::size_t(key[0]));
  }
  const TapTable copy = t;  // a copy holds the same table and knows it
  TapTable c = copy;
  EXPECT_FALSE(c.build(9, 20, 4, 1));
  EXPECT_TRUE(same(c, copy));
}

}  // namespace
}  // namespace temporal::upsample
