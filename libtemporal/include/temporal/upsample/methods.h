// The methods of the upsampling stage, as one table (libtemporal/src/upsample/registry.cpp). The table drives the
// tool's --method choices and --list-methods, the G-buffer layers read, the benchmark's variants and bound, the
// golden and reference tests, and pipelines/upsample-st.sh's METHODS names. Adding a method is one source file
// (its options, state, per-frame run and streamed bytes), one line of the table, and its section of
// docs/upsample-st.md.
#pragma once

#include <string>
#include <vector>

namespace temporal::upsample {

// A named way to run a method: the method and the arguments that select the variant, written as on the command
// line ("herzog-lagged" = --method herzog --lagged-wf).
struct MethodVariant {
  std::string name;
  std::string method;
  std::vector<std::string> args;
  std::string summary;
};

struct MethodInfo {
  std::string name;
  std::string summary;                  // one line, with the paper and its equations
  bool has_state = false;               // keeps anything between frames (--state-in / --state-out)
  std::vector<MethodVariant> variants;  // named variants besides the defaults
};

// Every method, in the order of --help and the docs.
const std::vector<MethodInfo>& methods();
// The method called `name`, or nullptr.
const MethodInfo* find_method(const std::string& name);
// Every method with its defaults (named after the method, no arguments) followed by its variants, in table
// order: what the benchmark and the tests run.
const std::vector<MethodVariant>& method_variants();
// The variant (or plain method) called `name`, or nullptr.
const MethodVariant* find_variant(const std::string& name);

// Variants any method takes, written as a name suffix ("herzog-demod" = herzog with --demodulate).
struct VariantSuffix {
  std::string suffix;  // "-demod"
  std::vector<std::string> args;
  std::string summary;
};
const std::vector<VariantSuffix>& variant_suffixes();

}  // namespace temporal::upsample
