// libFuzzer target: the EXR reader (temporal/io/exr.h) on every input: the header reader, then a whole read of
// every layer, then a read of one layer (the path the tools take when they read only the layers they need). Each
// call may succeed or return an error; AddressSanitizer and UBSan turn anything else (a read past a buffer, an
// allocation the size checks should have refused, an overflow) into a crash.
#include "fuzz_support.h"

#include "temporal/io/exr.h"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const std::string path = temporal::fuzz::write_input(data, size, "input.exr");
  auto info = temporal::read_exr_info(path);
  if (!info) return 0;
  auto all = temporal::read_exr(path);
  if (!all) return 0;
  const auto names = all->channel_names();
  if (names.empty()) return 0;
  temporal::ExrSelection one;
  one.layers = {names.back()};
  (void)temporal::read_exr(path, one);
  return 0;
}
