#include "temporal/core/image.h"
#include "temporal/core/parallel.h"

#include <gtest/gtest.h>

#include <sys/mman.h>

#include <cmath>
#include <cstdint>
#include <filesystem>
#include <fstream>
#include <limits>
#include <sstream>
#include <string>

namespace temporal {
namespace {

TEST(Image, ChannelsArePlanarAndAligned) {
  Image image(7, 3);
  float* r = image.add_channel("R", 1.0f);
  float* g = image.add_channel("G", 2.0f);
  ASSERT_NE(r, nullptr);
  ASSERT_NE(g, nullptr);
  EXPECT_EQ(reinterpret_cast<std::uintptr_t>(r) % 64, 0u);
  EXPECT_EQ(reinterpret_cast<std::uintptr_t>(g) % 64, 0u);
  EXPECT_EQ(image.pixel_count(), 21u);
  EXPECT_EQ(r[20], 1.0f);
  EXPECT_EQ(g[0], 2.0f);
  // Re-adding returns the same plane, untouched.
  r[5] = 9.0f;
  EXPECT_EQ(image.add_channel("R", 0.0f), r);
  EXPECT_EQ(r[5], 9.0f);
  // A uint channel is not visible as float and vice versa.
  image.add_uint_channel("id", 7u);
  EXPECT_EQ(image.plane("id"), nullptr);
  EXPECT_EQ(image.uint_plane("R"), nullptr);
  EXPECT_EQ(image.uint_plane("id")[3], 7u);
  EXPECT_EQ(image.add_channel("id"), nullptr);
}

// The VmFlags of the mapping that holds p (/proc/self/smaps), "" when not found.
std::string vm_flags_of(const void* p) {
  std::ifstream smaps("/proc/self/smaps");
  const auto a = reinterpret_cast<std::uintptr_t>(p);
  bool inside = false;
  for (std::string line; std::getline(smaps, line);) {
    std::uintptr_t lo = 0, hi = 0;
    char dash = 0;
    std::istringstream head(line);
    if (line.find(':') > line.find('-') && (head >> std::hex >> lo >> dash >> hi) && dash == '-') {
      inside = lo <= a && a < hi;
    } else if (inside && line.rfind("VmFlags:", 0) == 0) {
      return line.substr(8) + " ";
    }
  }
  return "";
}

TEST(Image, LargePlanesAskForHugePages) {
  // Every plane 64-byte aligned. 4 MiB and more: in a 2 MiB-aligned block advised for transparent huge pages, at a
  // staggered offset under 128 KiB into it (allocate_plane_memory), the same for Image's channels and PlaneVector's
  // planes; two planes allocated one after the other start on different L1 sets (offsets mod 4096 differ).
  PlaneVector<float> small(1000, 1.0f);
  EXPECT_EQ(reinterpret_cast<std::uintptr_t>(small.data()) % 64, 0u);
  PlaneVector<float> large(std::size_t(1280) * 1024);  // 5 MiB, zero-filled like std::vector
  Image image(1280, 1024);
  float* plane = image.add_channel("R", 3.0f);
  ASSERT_NE(plane, nullptr);
  for (const void* p : {static_cast<const void*>(large.data()), static_cast<const void*>(plane)}) {
    const auto a = reinterpret_cast<std::uintptr_t>(p);
    EXPECT_EQ(a % 64, 0u);
    EXPECT_LT(a % (std::uintptr_t(2) << 20), std::uintptr_t(128) << 10);
  }
  EXPECT_NE(reinterpret_cast<std::uintptr_t>(large.data()) % 4096, reinterpret_cast<std::uintptr_t>(plane) % 4096);
  EXPECT_EQ(large[large.size() - 1], 0.0f);
  EXPECT_EQ(plane[1280 * 1024 - 1], 3.0f);
  if (!std::filesystem::exists("/sys/kernel/mm/transparent_hugepage/enabled"))
    GTEST_SKIP() << "this kernel has no transparent huge pages: the advice is not checked";
  // A control region this test advises itself: where /proc does not show that advice (no VmFlags, or an emulator's
  // /proc such as qemu-user's, which lists the host's mappings), the planes' advice cannot be checked either.
  constexpr std::size_t kControl = std::size_t(4) << 20;
  void* control = mmap(nullptr, kControl, PROT_READ | PROT_WRITE, MAP_PRIVATE | MAP_ANONYMOUS, -1, 0);
  ASSERT_NE(control, MAP_FAILED);
  const bool shown = madvise(control, kControl, MADV_HUGEPAGE) == 0 &&
                     vm_flags_of(control).find(" hg ") != std::string::npos;
  munmap(control, kControl);
  if (!shown) GTEST_SKIP() << "/proc/self/smaps does not show MADV_HUGEPAGE here: the advice is not checked";
  // "hg": the mapping was advised MADV_HUGEPAGE (whether the kernel found free huge pages is its business).
  EXPECT_NE(vm_flags_of(large.data()).find(" hg "), std::string::npos) << vm_flags_of(large.data());
  EXPECT_NE(vm_flags_of(plane).find(" hg "), std::string::npos) << vm_flags_of(plane);
}

TEST(Image, CopyIsDeep) {
  Image a(2, 2);
  a.add_channel("R", 1.0f);
  Image b = a;
  b.plane("R")[0] = 5.0f;
  EXPECT_EQ(a.plane("R")[0], 1.0f);
}

TEST(Image, LayerChannels) {
  Image image(1, 1);
  for (const char* c : {"R", "G", "B", "N.X", "N.Y", "N.Z", "motion.X", "motion.Y", "id"}) image.add_channel(c);
  EXPECT_EQ(image.layer_channels("N"), (std::vector<std::string>{"N.X", "N.Y", "N.Z"}));
  EXPECT_EQ(image.layer_channels("motion"), (std::vector<std::string>{"motion.X", "motion.Y"}));
  // `rgb` is the bare colour channels, not every bare channel (before issue 21 it also took `id`).
  EXPECT_EQ(image.layer_channels("rgb"), (std::vector<std::string>{"R", "G", "B"}));
}

// The --layer rule of every tool (docs/conventions.md, "Layers").
TEST(Image, SelectLayers) {
  Image image(1, 1);
  for (const char* c : {"B", "A", "G", "R", "albedo.B", "albedo.R", "albedo.G", "ssao", "debug.mask", "N.Z", "N.X", "N.Y"})
    image.add_channel(c);
  image.add_uint_channel("id");
  auto pick = [&](const char* selection) { return select_layers(image, selection, "f.exr"); };
  EXPECT_EQ(*pick(""), (std::vector<std::string>{"R", "G", "B"}));
  EXPECT_EQ(*pick("rgb"), (std::vector<std::string>{"R", "G", "B"}));
  EXPECT_EQ(*pick("rgba"), (std::vector<std::string>{"R", "G", "B", "A"}));
  EXPECT_EQ(*pick("albedo"), (std::vector<std::string>{"albedo.R", "albedo.G", "albedo.B"}));  // R, G, B order
  EXPECT_EQ(*pick("N"), (std::vector<std::string>{"N.X", "N.Y", "N.Z"}));
  EXPECT_EQ(*pick("ssao"), (std::vector<std::string>{"ssao"}));              // a bare channel
  EXPECT_EQ(*pick("debug.mask"), (std::vector<std::string>{"debug.mask"}));  // one channel of a layer
  EXPECT_EQ(*pick("albedo,ssao"), (std::vector<std::string>{"albedo.R", "albedo.G", "albedo.B", "ssao"}));
  EXPECT_EQ(layer_items(""), (std::vector<std::string>{"rgb"}));
  EXPECT_EQ(layer_items("a,b"), (std::vector<std::string>{"a", "b"}));
  EXPECT_EQ(layer_names(image), (std::vector<std::string>{"rgb", "albedo", "ssao", "debug", "N", "id"}));

  auto missing = pick("motion");
  ASSERT_FALSE(missing);
  EXPECT_EQ(missing.error().kind, ErrorKind::Input);
  EXPECT_EQ(missing.error().file, "f.exr");
  EXPECT_EQ(missing.error().message, "no layer 'motion' (have: rgb, albedo, ssao, debug, N, id); pick another with --layer");
  EXPECT_FALSE(pick("id"));            // uint data
  EXPECT_FALSE(pick("rgb,R"));         // R twice
  EXPECT_FALSE(pick("albedo,,ssao"));  // an empty item
  Image grey(1, 1);
  grey.add_channel("R");
  grey.add_channel("G");
  EXPECT_FALSE(select_layers(grey, "rgb", "g.exr"));  // rgb needs all three
}

TEST(Image, CropCopiesTheRectangleAndZeroFillsOutside) {
  Image image(4, 3);
  float* v = image.add_channel("V");
  for (int i = 0; i < 12; ++i) v[i] = float(i);
  Image c = image.crop({1, 1, 2, 2});
  ASSERT_EQ(c.width(), 2);
  EXPECT_EQ(c.plane("V")[0], 5.0f);
  EXPECT_EQ(c.plane("V")[1], 6.0f);
  EXPECT_EQ(c.plane("V")[2], 9.0f);
  EXPECT_EQ(c.plane("V")[3], 10.0f);
  Image outside = image.crop({3, 2, 2, 2});
  EXPECT_EQ(outside.plane("V")[0], 11.0f);
  EXPECT_EQ(outside.plane("V")[1], 0.0f);
  EXPECT_EQ(outside.plane("V")[3], 0.0f);
  // Views crop without copying.
  auto view = image.view("V").crop({1, 1, 2, 2});
  EXPECT_EQ(view(1, 1), 10.0f);
  EXPECT_EQ(view.row(1), v + 9);
}

TEST(Image, InterleavedRoundTrip) {
  Image image(3, 2);
  const std::vector<std::string> names{"R", "G", "B"};
  std::vector<float> data(18);
  for (int i = 0; i < 18; ++i) data[i] = float(i);
  ASSERT_TRUE(image.from_interleaved(names, data));
  EXPECT_EQ(image.plane("G")[1], 4.0f);  // pixel 1, channel 1 = 1*3 + 1
  std::vector<float> back(18);
  ASSERT_TRUE(image.to_interleaved(names, back));
  EXPECT_EQ(back, data);
  const std::vector<std::string> missing{"X"};
  EXPECT_FALSE(image.to_interleaved(missing, back));
}

TEST(Image, CountsNonFinite) {
  std::vector<float> v{0.0f, std::numeric_limits<float>::quiet_NaN(), std::numeric_limits<float>::infinity(),
                       -std::numeric_limits<float>::infinity(), 1e30f};
  EXPECT_EQ(count_non_finite(v), 3u);
}

// A plane longer than one 2^20-value block of the 32-bit counts: non-finite values at the blocks' edges, and
// denormals and the largest floats, which are finite.
TEST(Image, CountsNonFiniteInLargePlanes) {
  std::vector<float> v((std::size_t(1) << 21) + 37, 1.0f);
  const std::size_t at[] = {0, 1000, (std::size_t(1) << 20) - 1, std::size_t(1) << 20, (std::size_t(1) << 21) - 1,
                            (std::size_t(1) << 21) + 36};
  for (std::size_t i = 0; i < std::size(at); ++i)
    v[at[i]] = i % 3 == 0 ? std::numeric_limits<float>::quiet_NaN()
               : i % 3 == 1 ? std::numeric_limits<float>::infinity()
                            : -std::numeric_limits<float>::infinity();
  v[5] = std::numeric_limits<float>::denorm_min();
  v[6] = std::numeric_limits<float>::max();
  v[7] = -std::numeric_limits<float>::max();
  EXPECT_EQ(count_non_finite(v), std::size(at));
  EXPECT_EQ(count_non_finite({v.data() + 1, std::size_t(1) << 20}), 3u);  // 1000, 2^20 - 1, 2^20
}

TEST(Parallel, RowsCoverEveryRowOnce) {
  std::vector<int> hits(1000, 0);
  parallel_rows(1000, [&](int y0, int y1) {
    for (int y = y0; y < y1; ++y) ++hits[y];
  });
  for (int h : hits) EXPECT_EQ(h, 1);
  ThreadLimit limit(1);
  EXPECT_EQ(max_threads(), 1);
}

}  // namespace
}  // namespace temporal
