// One CTest per method with a GPU implementation (tests/gpu/CMakeLists.txt, TEMPORAL_DEVICE_AGREEMENT): runs the
// TOOL itself with --device cpu and --device gpu on a small rendered sequence and checks, with `compare`, that
//  1. the two outputs agree to at least MIN_DB dB PSNR (RGB, peak 1) on every frame (`--fail-on worst`);
//  2. the headers say where each ran: temporal:device, temporal:computeClock, and on the GPU the gl* attributes
//     of its context (none on the CPU: the input's render attributes are not carried over);
//  3. for a method with state (--list-methods-json "stateful"): a GPU run's --state-out resumed on the CPU
//     (--state-in) and a CPU run's resumed on the GPU give, on the frames after the switch, what the uninterrupted
//     CPU run gave, at the same MIN_DB.
// Usage: device_agreement TOOL METHOD MIN_DB INPUTS WORK
//   INPUTS: render-gbuffer's gbuffer, shade and color sequences, frames 0-5 (the fixture device_inputs).
//        device_agreement --covers TOOL METHOD...
//   fails when a method of TOOL with a gpu implementation is not among the METHODs (the list has no line for it).
// Exit 0: agreement; 1: a check failed (the message says which); 77: this machine has no EGL device (CTest's
// SKIP_RETURN_CODE: the GPU cannot be tested here, the reason is printed).
#include "temporal/io/exr.h"
#include "test_support.h"

#include <nlohmann/json.hpp>

#include <algorithm>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <set>
#include <string>
#include <utility>
#include <vector>

namespace {

namespace fs = std::filesystem;
using temporal::test::run_command;
using temporal::test::tool_path;

constexpr int kSkip = 77;

std::string tool_name, method, inputs, work;
double min_db = 0.0;
int failures = 0;

void fail(const std::string& what) {
  std::cerr << "device_agreement " << tool_name << " " << method << ": " << what << "\n";
  ++failures;
}

// The tool's arguments that read the rendered inputs (upsample-st: the low-resolution shade; the others: the 1-spp
// colour), with the G-buffer (a method that reads none ignores it).
std::string input_args() {
  const std::string in = tool_name == "upsample-st" ? "shade" : "color";
  return " --input " + inputs + "/" + in + ".####.exr --gbuffer " + inputs + "/gbuffer.####.exr";
}

// Runs the tool on `device` for `frames` into DIR/o.####.exr; `extra` adds --state-in / --state-out. Returns the
// exit code; the output goes to `log`.
int run_tool(const std::string& device, const std::string& frames, const fs::path& dir, const std::string& extra,
             std::string& log) {
  fs::create_directories(dir);
  return run_command(tool_path(tool_name).string() + input_args() + " --method " + method + " --device " + device +
                         " --frames " + frames + " --out " + (dir / "o.####.exr").string() + extra,
                     &log);
}

// compare's worst-frame PSNR of `test` against `reference` (exit 0 required: above min_db on every frame).
void check_agreement(const fs::path& reference, const fs::path& test, const std::string& what) {
  const fs::path json = fs::path(work) / (what + ".json");
  std::string log;
  const int code = run_command(tool_path("compare").string() + " --reference " + (reference / "o.####.exr").string() +
                                   " " + (test / "o.####.exr").string() + " --json " + json.string() +
                                   " --fail-psnr " + std::to_string(min_db) + " --fail-on worst",
                               &log);
  std::string worst = "?";
  if (std::ifstream in(json); in) {
    const auto j = nlohmann::json::parse(in, nullptr, false);
    if (!j.is_discarded() && j.contains("sequences") && !j["sequences"].empty())
      worst = j["sequences"][0]["psnr_rgb"]["min"].dump();
  }
  std::cout << what << ": worst frame " << worst << " dB (bound " << min_db << " dB)\n";
  if (code != 0) fail(what + ": compare exited " + std::to_string(code) + " (3: below " + std::to_string(min_db) +
                      " dB on some frame): " + log);
}

// The header attributes of the first output in `dir`.
void check_header(const fs::path& dir, const std::string& device) {
  std::vector<fs::path> files;
  for (const auto& e : fs::directory_iterator(dir))
    if (e.path().extension() == ".exr") files.push_back(e.path());
  std::sort(files.begin(), files.end());
  if (files.empty()) return fail("no output in " + dir.string());
  auto img = temporal::read_exr(files.front().string());
  if (!img) return fail(img.error().message);
  const auto& extra = img->metadata().extra;
  auto attr = [&](const char* key) { return extra.count(key) ? extra.at(key) : std::string(); };
  if (attr("device") != device) fail(files.front().string() + ": temporal:device is '" + attr("device") + "', not " + device);
  const std::string clock = attr("computeClock");
  const bool gpu = device == "gpu";
  if (gpu ? (clock != "gpu (GL_TIME_ELAPSED)" && clock != "wall clock after glFinish") : clock != "wall clock")
    fail(files.front().string() + ": temporal:computeClock is '" + clock + "' on the " + device);
  for (const char* key : {"glContext", "glDevice", "glVendor", "glRenderer", "glVersion"})
    if (gpu == attr(key).empty())
      fail(files.front().string() + ": temporal:" + key + (gpu ? " is missing on the GPU" : " is there on the CPU ('" + attr(key) + "')"));
  if (!img->metadata().compute_ms) fail(files.front().string() + ": no temporal:computeMs");
  if (gpu) std::cout << "GPU: " << attr("glRenderer") << ", OpenGL " << attr("glVersion") << ", clock: " << clock << "\n";
}

// The method's row of `TOOL --list-methods-json`.
nlohmann::json method_row() {
  std::string text;
  if (run_command(tool_path(tool_name).string() + " --list-methods-json 2>/dev/null", &text) != 0) return {};
  const auto rows = nlohmann::json::parse(text, nullptr, false);
  if (rows.is_discarded()) return {};
  for (const auto& r : rows)
    if (r.value("name", "") == method) return r;
  return {};
}

// --covers: every method of the tool with a gpu implementation has its line.
int covers(int argc, char** argv) {
  tool_name = argv[2];
  const std::set<std::string> listed(argv + 3, argv + argc);
  std::string text;
  if (run_command(tool_path(tool_name).string() + " --list-methods-json 2>/dev/null", &text) != 0) {
    std::cerr << tool_name << " --list-methods-json failed: " << text << "\n";
    return 1;
  }
  const auto rows = nlohmann::json::parse(text, nullptr, false);
  if (rows.is_discarded()) {
    std::cerr << tool_name << " --list-methods-json is not JSON: " << text << "\n";
    return 1;
  }
  int missing = 0;
  for (const auto& r : rows) {
    if (!r.contains("method") || r.value("name", "") != r.value("method", "")) continue;  // variants, suffixes
    const auto devices = r.value("implementations", std::vector<std::string>{});
    if (std::find(devices.begin(), devices.end(), "gpu") == devices.end() || listed.count(r["name"])) continue;
    std::cerr << tool_name << " --method " << r["name"].get<std::string>()
              << " has a gpu implementation but no --device test: add the line \"" << tool_name << " "
              << r["name"].get<std::string>() << " MIN_DB\" to TEMPORAL_DEVICE_AGREEMENT in tests/gpu/CMakeLists.txt\n";
    ++missing;
  }
  if (!missing) std::cout << tool_name << ": every method with a gpu implementation has a --device test\n";
  return missing ? 1 : 0;
}

}  // namespace

int main(int argc, char** argv) {
  if (argc >= 3 && std::string(argv[1]) == "--covers") return covers(argc, argv);
  if (argc != 6) {
    std::cerr << "usage: device_agreement TOOL METHOD MIN_DB INPUTS WORK\n";
    return 2;
  }
  tool_name = argv[1];
  method = argv[2];
  min_db = std::atof(argv[3]);
  inputs = argv[4];
  work = argv[5];
  fs::remove_all(work);
  fs::create_directories(work);

  const nlohmann::json row = method_row();
  if (row.is_null()) {
    fail("not a method of " + tool_name + " --list-methods-json");
    return 1;
  }
  const auto devices = row.value("implementations", std::vector<std::string>{});
  if (std::find(devices.begin(), devices.end(), "gpu") == devices.end()) {
    fail("its registry entry has no gpu implementation (implementations: " + row["implementations"].dump() +
         "): register it ({kGpuDevice, factory}) or remove its line from TEMPORAL_DEVICE_AGREEMENT");
    return 1;
  }

  const fs::path cpu = fs::path(work) / "cpu", gpu = fs::path(work) / "gpu";
  std::string log;
  if (run_tool("gpu", "0-5", gpu, "", log) != 0) {
    // Only the context's own errors skip (temporal/gpu/context.cpp: no libEGL, no device, no 4.5 context).
    if (log.find("--device gpu:") != std::string::npos) {
      std::cout << "skipped: this machine cannot run --device gpu: " << log;
      return kSkip;
    }
    fail("--device gpu failed: " + log);
    return 1;
  }
  if (run_tool("cpu", "0-5", cpu, "", log) != 0) {
    fail("--device cpu failed: " + log);
    return 1;
  }
  check_header(cpu, "cpu");
  check_header(gpu, "gpu");
  check_agreement(cpu, gpu, "gpu-vs-cpu");

  if (row.value("stateful", false)) {
    // Frames 0-2 on one device, the state file, frames 3-5 on the other; the reference is the uninterrupted CPU
    // run's frames 3-5 (in a folder of their own: compare reads every frame of its reference pattern).
    const fs::path ref = fs::path(work) / "cpu-3-5";
    fs::create_directories(ref);
    for (int f = 3; f <= 5; ++f) {
      char name[32];
      std::snprintf(name, sizeof name, "o.%04d.exr", f);
      fs::copy_file(cpu / name, ref / name);
    }
    for (const auto& [first, second] : {std::pair<std::string, std::string>{"gpu", "cpu"}, {"cpu", "gpu"}}) {
      const std::string what = first + "-state-then-" + second;
      const fs::path state = fs::path(work) / (what + ".state.exr");
      if (run_tool(first, "0-2", fs::path(work) / (what + "-head"), " --state-out " + state.string(), log) != 0) {
        fail(what + ": the " + first + " run with --state-out failed: " + log);
        continue;
      }
      const fs::path tail = fs::path(work) / what;
      if (run_tool(second, "3-5", tail, " --state-in " + state.string(), log) != 0) {
        fail(what + ": the " + second + " run with --state-in failed: " + log);
        continue;
      }
      check_agreement(ref, tail, what);
    }
  }
  if (failures) return 1;
  std::cout << "device_agreement " << tool_name << " " << method << ": ok\n";
  return 0;
}
