// libFuzzer target: the EXR reader (temporal/io/exr.h) on every input: the header reader, then a whole read of
// every layer, then a read of one layer (the path the tools take when they read only the layers they need). Each
// call may succeed or return an error; AddressSanitizer and UBSan turn anything else (a read past a buffer, an
// allocation the size checks should have refused, an overflow) into a crash.
//
// The input is read from memory (read_exr's buffer overloads: OpenEXR's core through its read callbacks, OpenImageIO
// through an IOMemReader) with every check of the file readers. Through a file per execution the target ran at
// 35-150 executions/s (issue 26).
#include "temporal/io/exr.h"

#include <cstdint>
#include <span>

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const std::span<const std::uint8_t> bytes(data, size);
  const std::string name = "input.exr";
  auto info = temporal::read_exr_info(bytes, name);
  if (!info) return 0;
  auto all = temporal::read_exr(bytes, name);
  if (!all) return 0;
  const auto names = all->channel_names();
  if (names.empty()) return 0;
  temporal::ExrSelection one;
  one.layers = {names.back()};
  (void)temporal::read_exr(bytes, name, one);
  return 0;
}
