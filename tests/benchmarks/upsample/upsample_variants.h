// The upsampling variants the benchmark and the golden-check tool run, from the stage's method table
// (temporal/upsample/methods.h): every method with its defaults and each named variant (herzog-lagged,
// drobot-refresh, ...).
#pragma once

#include "temporal/upsample/methods.h"
#include "temporal/upsample/upsample.h"

#include <cstdio>
#include <cstdlib>
#include <string>
#include <vector>

namespace temporal::test {

// Options of a variant with extra command-line style arguments; aborts on a name or argument the table does not
// know (a broken benchmark definition, not a runtime condition).
inline upsample::Options upsample_variant(const std::string& name, std::vector<std::string> extra = {}) {
  const upsample::MethodVariant* v = upsample::find_variant(name);
  if (!v) {
    std::fprintf(stderr, "no upsampling variant '%s'\n", name.c_str());
    std::abort();
  }
  std::vector<std::string> args = v->args;
  args.insert(args.end(), extra.begin(), extra.end());
  auto o = upsample::make_options(v->method, args);
  if (!o) {
    std::fprintf(stderr, "variant '%s': %s\n", name.c_str(), o.error().message.c_str());
    std::abort();
  }
  return *o;
}

}  // namespace temporal::test
