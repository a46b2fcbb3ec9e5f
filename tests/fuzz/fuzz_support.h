// Shared by the libFuzzer targets of tests/fuzz: a per-process scratch folder (for loaders that take a path)
// and writing one input there. Each target is one file: LLVMFuzzerTestOneInput feeds the bytes to a reader
// and lets it succeed or return an error; AddressSanitizer and UBSan turn anything else into a crash.
#pragma once

#include <unistd.h>

#include <cstdint>
#include <cstdio>
#include <filesystem>
#include <string>

namespace temporal::fuzz {

// A folder private to this process (in /dev/shm when it exists: inputs are written once per execution).
inline const std::filesystem::path& scratch() {
  static const std::filesystem::path dir = [] {
    const std::filesystem::path base = std::filesystem::exists("/dev/shm") ? "/dev/shm" : std::filesystem::temp_directory_path();
    auto d = base / ("temporal_fuzz_" + std::to_string(getpid()));
    std::filesystem::create_directories(d);
    return d;
  }();
  return dir;
}

// Writes the input to scratch()/name and returns the path.
inline std::string write_input(const std::uint8_t* data, std::size_t size, const std::string& name) {
  const std::string path = (scratch() / name).string();
  if (std::FILE* f = std::fopen(path.c_str(), "wb")) {
    if (size) std::fwrite(data, 1, size, f);
    std::fclose(f);
  }
  return path;
}

}  // namespace temporal::fuzz
