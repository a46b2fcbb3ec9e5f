#include "test_support.h"

#include <cstdlib>

#include "temporal/io/exr.h"

#include <sys/wait.h>

#include <array>
#include <cmath>
#include <cstdio>
#include <fstream>
#include <sstream>

namespace temporal::test {

std::filesystem::path source_dir() { return TEMPORAL_SOURCE_DIR; }
std::filesystem::path binary_dir() { return TEMPORAL_BINARY_DIR; }

std::filesystem::path tool_path(const std::string& tool) { return binary_dir() / "apps" / tool / tool; }

std::filesystem::path scratch_dir(const std::string& name) {
  // TEMPORAL_TEST_SCRATCH: another root, for a second run of the same executable that CTest may start beside the
  // first (the runs on emulated CPUs, tests/emulated): each run removes and refills its folders.
  const char* root = std::getenv("TEMPORAL_TEST_SCRATCH");
  auto dir = (root && *root ? std::filesystem::path(root) : binary_dir() / "test-scratch") / name;
  std::error_code ec;
  std::filesystem::remove_all(dir, ec);
  std::filesystem::create_directories(dir);
  return dir;
}

std::optional<std::filesystem::path> shared_assets() {
  // TEMPORAL_SHARED_ASSETS overrides the default place (a worktree or checkout elsewhere than beside ../shared).
  if (const char* env = std::getenv("TEMPORAL_SHARED_ASSETS"); env && *env && std::filesystem::is_directory(env))
    return std::filesystem::canonical(env);
  auto dir = source_dir() / ".." / "shared" / "assets";
  if (std::filesystem::is_directory(dir)) return std::filesystem::canonical(dir);
  return std::nullopt;
}

Image make_image(int width, int height, const std::vector<std::string>& channels, float fill) {
  Image image(width, height);
  for (const auto& c : channels) image.add_channel(c, fill);
  return image;
}

::testing::AssertionResult images_near(const Image& actual, const Image& expected,
                                       const std::vector<std::string>& channels, float max_abs_error,
                                       const std::string& label) {
  if (actual.width() != expected.width() || actual.height() != expected.height())
    return ::testing::AssertionFailure() << label << ": size " << actual.width() << "x" << actual.height()
                                         << " != expected " << expected.width() << "x" << expected.height();
  Image diff(actual.width(), actual.height());
  float worst = 0.0f;
  int worst_x = 0, worst_y = 0;
  std::string worst_channel;
  for (const auto& c : channels) {
    const float* a = actual.plane(c);
    const float* e = expected.plane(c);
    if (!a || !e) return ::testing::AssertionFailure() << label << ": channel " << c << " missing";
    float* d = diff.add_channel(c);
    for (std::size_t i = 0; i < actual.pixel_count(); ++i) {
      d[i] = std::fabs(a[i] - e[i]);
      const bool bad = std::isnan(d[i]) != false || d[i] > worst;
      if (bad) {
        worst = std::isnan(d[i]) ? INFINITY : d[i];
        worst_x = int(i % actual.width());
        worst_y = int(i / actual.width());
        worst_channel = c;
      }
    }
  }
  if (worst <= max_abs_error) return ::testing::AssertionSuccess();
  const auto path = scratch_dir("failures-" + label) / (label + ".diff.exr");
  (void)write_exr(path.string(), diff);
  return ::testing::AssertionFailure() << label << ": max |difference| " << worst << " > " << max_abs_error
                                       << " at (" << worst_x << "," << worst_y << ") channel " << worst_channel
                                       << "; difference image: " << path.string();
}

std::string read_file(const std::filesystem::path& path) {
  std::ifstream in(path, std::ios::binary);
  std::stringstream s;
  s << in.rdbuf();
  return s.str();
}

std::string base64(const std::vector<unsigned char>& data) {
  static const char* t = "ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789+/";
  std::string out;
  for (std::size_t i = 0; i < data.size(); i += 3) {
    unsigned v = unsigned(data[i]) << 16;
    if (i + 1 < data.size()) v |= unsigned(data[i + 1]) << 8;
    if (i + 2 < data.size()) v |= data[i + 2];
    out += t[(v >> 18) & 63];
    out += t[(v >> 12) & 63];
    out += i + 1 < data.size() ? t[(v >> 6) & 63] : '=';
    out += i + 2 < data.size() ? t[v & 63] : '=';
  }
  return out;
}

int run_command(const std::string& command, std::string* output) {
  const std::string full = command + " 2>&1";
  FILE* pipe = popen(full.c_str(), "r");
  if (!pipe) return -1;
  std::array<char, 4096> buffer{};
  std::string text;
  while (std::fgets(buffer.data(), int(buffer.size()), pipe)) text += buffer.data();
  const int status = pclose(pipe);
  if (output) *output = text;
  return WIFEXITED(status) ? WEXITSTATUS(status) : -1;
}

}  // namespace temporal::test
