// The gpu stage: the EGL context, image buffers, program errors, timers, and the GLSL reprojection snippet against
// temporal/core/reproject.h on random motion, depth and id fields (the rules every GPU kernel inherits).
#include "gpu_support.h"
#include "temporal/core/reproject.h"
#include "temporal/gpu/buffer.h"
#include "temporal/gpu/glsl.h"
#include "temporal/gpu/program.h"
#include "temporal/gpu/timer.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cstring>
#include <limits>
#include <random>
#include <vector>

namespace {

using namespace temporal;

TEST(GpuStage, ContextDescribesItsDevice) {
  TEMPORAL_GPU_CONTEXT_OR_SKIP(ctx);
  EXPECT_FALSE(ctx->renderer().empty());
  EXPECT_EQ(ctx->version().rfind("4.", 0), 0u) << ctx->version();
  EXPECT_NE(ctx->description().find(ctx->renderer()), std::string::npos);
  EXPECT_GE(ctx->max_storage_bytes(), 1 << 24);  // the GL 4.3 minimum
  gpu::Timer timer(ctx);
  EXPECT_EQ(timer.clock() == gpu::Clock::GpuQuery, ctx->timer_queries());
  // Mesa's llvmpipe reads 0 from GL_TIME_ELAPSED: it must be timed by the wall clock.
  if (ctx->software()) {
    EXPECT_EQ(timer.clock(), gpu::Clock::WallAfterFinish);
  }
  EXPECT_TRUE(ctx->check("test"));
}

TEST(GpuStage, DeviceIndexOutOfRangeIsAUsageError) {
  gpu::ContextOptions options;
  options.device = 99;
  auto ctx = gpu::Context::create(options);
  ASSERT_FALSE(ctx);
  EXPECT_EQ(ctx.error().kind, ErrorKind::Usage);
}

TEST(GpuStage, ImageBufferRoundTripsFloatAndUintPlanesBitForBit) {
  TEMPORAL_GPU_CONTEXT_OR_SKIP(ctx);
  Image img(7, 5);
  float* f = img.add_channel("R");
  std::uint32_t* u = img.add_uint_channel("id");
  for (std::size_t i = 0; i < img.pixel_count(); ++i) {
    f[i] = float(i) * 0.37f - 3.0f;
    u[i] = 0xFFFFFFFFu - std::uint32_t(i) * 0x01010101u;  // ids above 2^24 and NaN-pattern bits survive
  }
  f[3] = std::numeric_limits<float>::quiet_NaN();
  f[4] = -std::numeric_limits<float>::infinity();
  auto buf = gpu::ImageBuffer::create(ctx, 7, 5, 2);
  ASSERT_TRUE(buf) << buf.error().message;
  ASSERT_TRUE(buf->upload(0, img, "R"));
  ASSERT_TRUE(buf->upload(1, img, "id"));
  Image back(7, 5);
  ASSERT_TRUE(buf->download(0, back, "R"));
  ASSERT_TRUE(buf->download(1, back, "id", true));
  EXPECT_EQ(std::memcmp(back.plane("R"), f, img.pixel_count() * 4), 0);
  EXPECT_EQ(std::memcmp(back.uint_plane("id"), u, img.pixel_count() * 4), 0);
  EXPECT_FALSE(buf->upload(0, img, "G"));  // a missing channel is an error, not garbage
  EXPECT_FALSE(buf->download(2, back, "X"));
}

// create_all / create_all_cleared (the buffers of one frame size made together): every buffer its shape, cleared
// when asked; one that cannot be made (past the device's storage block size) leaves every buffer as it was.
TEST(GpuStage, ImageBufferSetIsMadeWholeOrNotAtAll) {
  TEMPORAL_GPU_CONTEXT_OR_SKIP(ctx);
  gpu::ImageBuffer a, b;
  ASSERT_TRUE(gpu::ImageBuffer::create_all_cleared(ctx, {{&a, 5, 3, 2}, {&b, 7, 1, 1}}));
  EXPECT_EQ(a.width(), 5);
  EXPECT_EQ(a.height(), 3);
  EXPECT_EQ(a.planes(), 2);
  EXPECT_EQ(b.width(), 7);
  EXPECT_EQ(b.planes(), 1);
  std::vector<float> plane(a.pixel_count(), 1.0f);
  ASSERT_TRUE(a.download(1, plane.data()));
  EXPECT_EQ(std::count(plane.begin(), plane.end(), 0.0f), 15);
  const int too_many = int(ctx->max_storage_bytes() / (16 * 16 * 4)) + 1;
  const Status s = gpu::ImageBuffer::create_all(ctx, {{&a, 16, 16, 1}, {&b, 16, 16, too_many}});
  ASSERT_FALSE(s);
  EXPECT_NE(s.error().message.find("exceeds the device's storage block size"), std::string::npos) << s.error().message;
  EXPECT_EQ(a.width(), 5);
  EXPECT_EQ(a.planes(), 2);
  EXPECT_EQ(b.width(), 7);
}

TEST(GpuStage, CompileErrorsCarryTheDriversLog) {
  TEMPORAL_GPU_CONTEXT_OR_SKIP(ctx);
  auto p = gpu::Program::compile(ctx, "broken", {gpu::glsl::prelude(), "void main() { undeclared_name = 1; }\n"});
  ASSERT_FALSE(p);
  EXPECT_NE(p.error().message.find("'broken' does not compile"), std::string::npos) << p.error().message;
  EXPECT_NE(p.error().message.find("undeclared_name"), std::string::npos) << p.error().message;
}

// A kernel that runs the snippet's functions per pixel and writes what they return: the reprojection of plane
// `val` (the shared rules, as warp_planes), its hit flag, and the bilinear, Catmull-Rom and nearest fetches at
// p + motion.
constexpr const char* kProbe = R"(
uniform uint u_n;
uniform bool u_use_depth, u_use_ids;
uniform float u_tol;
// in: motion.X, motion.Y, z (expected), id, prev z, prev id, val
#define REPROJECT_PREV_Z(q) inp[4u * u_n + uint(q)]
#define REPROJECT_PREV_ID(q) inp_u[5u * u_n + uint(q)]
)";
constexpr const char* kProbeMain = R"(
void main() {
  ivec2 p;
  uint i;
  if (!pixel_index(p, i)) return;
  const vec2 m = vec2(inp[i], inp[u_n + i]);
  Taps t = reproject_taps(p, m);
  const bool hit = reproject_test(t, inp[2u * u_n + i], inp_u[3u * u_n + i], u_use_depth, u_use_ids, u_tol);
  outp[i] = hit ? REPROJECT_GATHER(inp, 6u * u_n, t) : uintBitsToFloat(0x7fc00000u);
  outp[u_n + i] = hit ? 1.0 : 0.0;
  const vec2 f = vec2(float(p.x) + m.x, float(p.y) + m.y);
  if (reproject_on_screen(f)) {
    const Taps b = reproject_bilinear(f);
    outp[2u * u_n + i] = REPROJECT_GATHER(inp, 6u * u_n, b);
    const CatmullRom c = catmull_rom(f);
    CATMULL_ROM_FETCH(outp[3u * u_n + i], inp, 6u * u_n, c)
    outp[4u * u_n + i] = inp[6u * u_n + uint(reproject_nearest(f))];
  } else {
    outp[2u * u_n + i] = 0.0;
    outp[3u * u_n + i] = 0.0;
    outp[4u * u_n + i] = 0.0;
  }
}
)";

struct ProbeCase {
  bool depth, ids;
};

TEST(GpuStage, GlslReprojectionFollowsTheCppRules) {
  TEMPORAL_GPU_CONTEXT_OR_SKIP(ctx);
  const int W = 37, H = 29;  // not multiples of the 16 x 16 work group
  const std::size_t n = std::size_t(W) * H;
  std::mt19937 rng(7);
  std::uniform_real_distribution<float> motion(-6.0f, 6.0f), depth(5.0f, 6.0f), val(0.0f, 1.0f);
  std::vector<float> mx(n), my(n), z(n), pz(n), v(n);
  std::vector<std::uint32_t> id(n), pid(n);
  for (std::size_t i = 0; i < n; ++i) {
    mx[i] = motion(rng);
    my[i] = motion(rng);
    // Quarter-pixel motions land on exact pixel centres and tap borders; whole ones on exact centres.
    if (i % 5 == 0) mx[i] = std::round(mx[i] * 4.0f) / 4.0f;
    if (i % 7 == 0) my[i] = std::round(my[i]);
    z[i] = depth(rng);
    pz[i] = depth(rng) * (i % 3 == 0 ? 1.3f : 1.0f);  // some taps fail the 5 % test
    id[i] = std::uint32_t(i % 4 == 0 ? 2 : 1);
    pid[i] = std::uint32_t(i % 6 == 0 ? 2 : 1);
    v[i] = val(rng);
  }
  mx[10] = std::numeric_limits<float>::quiet_NaN();
  my[11] = std::numeric_limits<float>::infinity();
  mx[12] = 2e6f;
  mx[13] = -0.5f;  // exactly on the off-screen border for x = 0 rows
  for (int y = 0; y < H; ++y) mx[std::size_t(y) * W] = -0.5f;  // u = -0.5: on screen (inclusive rule)
  for (int y = 0; y < H; ++y) mx[std::size_t(y) * W + W - 1] = 0.5f;  // u = W - 0.5: off screen

  auto in = gpu::ImageBuffer::create(ctx, W, H, 7);
  auto out = gpu::ImageBuffer::create(ctx, W, H, 5);
  ASSERT_TRUE(in && out);
  ASSERT_TRUE(in->upload(0, mx.data()) && in->upload(1, my.data()) && in->upload(2, z.data()) &&
              in->upload(3, id.data()) && in->upload(4, pz.data()) && in->upload(5, pid.data()) &&
              in->upload(6, v.data()));
  auto program = gpu::Program::compile(ctx, "probe",
                                       {gpu::glsl::prelude(), gpu::glsl::storage(0, "inp"),
                                        gpu::glsl::storage(1, "outp"), kProbe, gpu::glsl::reproject(), kProbeMain});
  ASSERT_TRUE(program) << program.error().message;
  for (const ProbeCase pc : {ProbeCase{true, true}, ProbeCase{true, false}, ProbeCase{false, true},
                             ProbeCase{false, false}}) {
    SCOPED_TRACE(std::string("depth ") + (pc.depth ? "on" : "off") + ", ids " + (pc.ids ? "on" : "off"));
    ASSERT_TRUE(program->use());
    program->set("u_n", std::uint32_t(n));
    program->set("u_use_depth", int(pc.depth));
    program->set("u_use_ids", int(pc.ids));
    program->set("u_tol", reproject::kDepthTolerance);
    in->bind(0);
    out->bind(1);
    ASSERT_TRUE(program->dispatch(W, H));
    std::vector<float> got(n * 5);
    for (int k = 0; k < 5; ++k) ASSERT_TRUE(out->download(k, got.data() + std::size_t(k) * n));

    reproject::Frames frames;
    frames.width = W;
    frames.height = H;
    frames.motion_x = mx.data();
    frames.motion_y = my.data();
    frames.z = pc.depth ? z.data() : nullptr;
    frames.prev_z = pc.depth ? pz.data() : nullptr;
    frames.id = pc.ids ? id.data() : nullptr;
    frames.prev_id = pc.ids ? pid.data() : nullptr;
    frames.test = {reproject::kDepthTolerance, pc.ids};
    std::vector<float> warped(n);
    const float* prev[1] = {v.data()};
    float* outs[1] = {warped.data()};
    reproject::warp_planes(frames, prev, outs);
    std::size_t hits = 0;
    for (std::size_t i = 0; i < n; ++i) {
      const int x = int(i % W), y = int(i / W);
      // Hit or miss: the same decision for every pixel.
      ASSERT_EQ(std::isfinite(warped[i]), got[n + i] > 0.0f) << "pixel " << x << "," << y;
      hits += std::isfinite(warped[i]) ? 1 : 0;
      // The fetched value: the same weights and taps; a driver may fuse the weighted sum into FMAs where GCC does
      // not (or the other way round): a few float ulps of values in [0, 1].
      if (std::isfinite(warped[i])) {
        EXPECT_NEAR(got[i], warped[i], 2e-6f) << "pixel " << x << "," << y;
      }
      const float fx = float(x) + mx[i], fy = float(y) + my[i];
      if (reproject::on_screen(fx, fy, W, H)) {
        EXPECT_NEAR(got[2 * n + i], reproject::bilinear(fx, fy, W, H)(v.data()), 2e-6f);
        EXPECT_NEAR(got[3 * n + i], reproject::catmull_rom(fx, fy, W, H)(v.data()), 4e-6f);
        EXPECT_EQ(got[4 * n + i], v[reproject::nearest(fx, fy, W, H)]);
      }
    }
    EXPECT_GT(hits, n / 4);      // the case exercises hits ...
    EXPECT_LT(hits, n - n / 10);  // ... and misses
  }
}

TEST(GpuStage, TimerMeasuresADispatch) {
  TEMPORAL_GPU_CONTEXT_OR_SKIP(ctx);
  auto program = gpu::Program::compile(
      ctx, "busy",
      {gpu::glsl::prelude(), gpu::glsl::storage(0, "b"),
       "void main() { ivec2 p; uint i; if (!pixel_index(p, i)) return; float x = b[i];\n"
       "  for (int k = 0; k < 512; ++k) x = x * 0.999 + 0.001; b[i] = x; }\n"});
  ASSERT_TRUE(program) << program.error().message;
  auto buf = gpu::ImageBuffer::create(ctx, 256, 256, 1);
  ASSERT_TRUE(buf && buf->clear(0, 1));
  gpu::Timer timer(ctx);
  ASSERT_TRUE(program->use());
  buf->bind(0);
  timer.start();
  ASSERT_TRUE(program->dispatch(256, 256));
  const double ms = timer.stop_ms();
  EXPECT_GT(ms, 0.0);
  EXPECT_LT(ms, 60000.0);
  std::vector<float> got(256 * 256);
  ASSERT_TRUE(buf->download(0, got.data()));
  EXPECT_GT(got[1000], 0.3f);  // the kernel ran: 1 - 0.999^512 = 0.40
}

}  // namespace
