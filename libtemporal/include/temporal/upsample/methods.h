// The methods of the upsampling stage, as one table (libtemporal/src/upsample/registry.cpp), in the pattern every
// stage shares (temporal/core/method.h). The table drives the tool's --method choices, --help, --list-methods and
// --list-methods-json, the G-buffer layers read, the benchmark's variants and bound, the golden and reference
// tests, and pipelines/upsample-st.sh's METHODS names. Adding a method is one source file (its MethodEntry: info,
// options, layers, implementations, streamed bytes), its line in registry.cpp, and its section of
// docs/upsample-st.md.
#pragma once

#include "temporal/core/method.h"
#include "temporal/core/stage.h"
#include "temporal/upsample/upsample.h"

#include <cstddef>
#include <memory>
#include <string>
#include <string_view>
#include <vector>

namespace temporal::upsample {

using temporal::Implementation;
using temporal::MethodInfo;
using temporal::MethodVariant;

class MethodState;  // a method's per-frame work and history (libtemporal/src/upsample/method.h)
struct Geometry;    // the sizes a state is allocated for (same file)

// A method's state for frames of one geometry, on one device: a CPU factory
// `std::unique_ptr<MethodState> (const Options&, const Geometry&)` or a GPU one
// `Expected<std::unique_ptr<MethodState>> (std::shared_ptr<gpu::Context>, const Options&, const Geometry&)`
// (src/upsample/gpu_methods.h), listed as `{kGpuDevice, make_NAME_state_gpu}` in the method's entry: the tool's
// --device picks the implementation (temporal/core/method.h, DeviceFactory).
using StateFactory = DeviceFactory<MethodState, const Options&, const Geometry&>;

// One row of the registry (docs/upsample-st.md, "Methods as units").
struct MethodEntry {
  MethodInfo info;
  // The method's own parameters with their defaults (nullptr: none).
  std::unique_ptr<MethodOptions> (*make_options)() = nullptr;
  // G-buffer layers it reads (albedo for demodulation is added by the Upsampler).
  std::vector<LayerNeed> (*layers)(const Options&) = nullptr;
  // Its implementations: a state for frames of a geometry, per device ("cpu", "gpu").
  std::vector<Implementation<StateFactory>> implementations = {};
  // Bytes per frame it must at least read and write (the benchmark's streaming bound): G-buffer planes, payload in
  // and out, histories read and written once. W, H full resolution, k the factor, C payload channels.
  std::size_t (*streamed_bytes)(const Options&, int W, int H, int k, int C) = nullptr;
  // Header attributes of a state that must match the options of the run that loads it ("mode=cache"); nullptr
  // when the state does not depend on the options.
  std::string (*state_layout)(const Options&) = nullptr;
  // The `temporal:method` header value when it is more than the name ("drobot-refresh"); nullptr: the name.
  std::string (*header_name)(const Options&) = nullptr;
};

// Every method, in the order of --help and the docs.
const std::vector<const MethodEntry*>& registry();
// The method called `name`, or nullptr.
const MethodEntry* find_entry(std::string_view name);
// Every method with its defaults (named after the method, no arguments) followed by its variants, in table
// order: what the benchmark and the tests run.
const std::vector<MethodVariant>& method_variants();
// The variant (or plain method) called `name`, or nullptr.
const MethodVariant* find_variant(std::string_view name);

// Variants any method takes, written as a name suffix ("herzog-demod" = herzog with --demodulate).
struct VariantSuffix {
  std::string suffix;  // "-demod"
  std::vector<std::string> args;
  std::string summary;
};
const std::vector<VariantSuffix>& variant_suffixes();

}  // namespace temporal::upsample
