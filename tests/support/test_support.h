// Helpers shared by the test suites: scratch folders, optional third-party assets, image comparisons that
// write a difference EXR when they fail.
#pragma once

#include "temporal/core/image.h"
#include "temporal/core/method.h"

#include <gtest/gtest.h>

#include <filesystem>
#include <optional>
#include <string>
#include <utility>
#include <vector>

namespace temporal::test {

// A fresh, empty folder under the build tree (or $TEMPORAL_TEST_SCRATCH) for one test (removed and recreated on
// each call).
std::filesystem::path scratch_dir(const std::string& name);

// ../shared/assets beside the project (or $TEMPORAL_SHARED_ASSETS), when present. Tests that need it call
// GTEST_SKIP() otherwise:
//   auto assets = shared_assets(); if (!assets) GTEST_SKIP() << "../shared/assets is absent";
std::optional<std::filesystem::path> shared_assets();

// The project's source folder (for assets/ and docs/).
std::filesystem::path source_dir();
// The build folder (for the built tools: binary_dir() / "apps/compare/compare").
std::filesystem::path binary_dir();
// Path of a built tool, e.g. tool_path("compare").
std::filesystem::path tool_path(const std::string& tool);

// An image with the named float channels, every value `fill`.
Image make_image(int width, int height, const std::vector<std::string>& channels, float fill = 0.0f);

// Compares the named float channels. Passes when max |a - e| <= max_abs_error for every channel; otherwise
// writes `<scratch>/<label>.diff.exr` (per-channel absolute difference) and reports the worst pixel.
::testing::AssertionResult images_near(const Image& actual, const Image& expected,
                                       const std::vector<std::string>& channels, float max_abs_error,
                                       const std::string& label);

// The devices of a method's registry entry as --list-methods prints them ("cpu,gpu") and as --list-methods-json
// lists them ("\"implementations\": [\"cpu\", \"gpu\"]"), for the method tools' CLI tests.
template <typename Entry>
std::pair<std::string, std::string> device_lists(const Entry& e) {
  std::string text, json;
  for (const auto& d : implementation_devices(e)) {
    text += (text.empty() ? "" : ",") + d;
    json += (json.empty() ? "" : ", ") + ("\"" + d + "\"");
  }
  return {text, "\"implementations\": [" + json + "]"};
}

// The line --list-methods prints for a method with its defaults: name, arguments, summary, devices, tab-separated.
template <typename Entry>
std::string list_methods_line(const Entry& e) {
  return e.info.name + "\t--method " + e.info.name + "\t" + e.info.summary + "\t" + device_lists(e).first + "\n";
}

// The whole file as bytes (empty when it cannot be read).
std::string read_file(const std::filesystem::path& path);

// RFC 4648 base64 with '=' padding (the data: URIs of the glTF scenes the tests write).
std::string base64(const std::vector<unsigned char>& data);

// Runs a shell command, returns its exit code; stdout+stderr are captured into `output` when given.
int run_command(const std::string& command, std::string* output = nullptr);

}  // namespace temporal::test
