// The methods of `filter-phlm` as units: one registry line per method (src/phlm/registry.cpp), each with its
// parameters, the G-buffer layers it reads and a factory; adding a method is one source file, one registry line and
// its section in docs/filter-phlm.md. The tool binds every method's parameters to its command line from here, and
// runs the chosen method through the sequence runner (temporal/io/runner.h).
#pragma once

#include "temporal/core/params.h"
#include "temporal/core/stage.h"
#include "temporal/phlm/ema.h"
#include "temporal/phlm/frame_filter.h"
#include "temporal/phlm/fxaa.h"
#include "temporal/phlm/phlm.h"
#include "temporal/phlm/taa.h"

#include <memory>
#include <string>
#include <string_view>
#include <vector>

namespace temporal {

// Every option of filter-phlm. The defaults are those of each method's parameter struct.
struct FilterOptions {
  std::string method = "phlm";
  std::string layer = "rgb";  // rgb (R,G,B) or a layer name (ssao, shadow, direct, ...)
  bool debug_layers = false;
  PhlmParams phlm;
  TaaParams taa;
  EmaParams ema;
  FxaaParams fxaa;
};

// One method of filter-phlm.
struct FilterMethod {
  const char* name;     // --method value
  const char* summary;  // one line for --help and the docs
  // G-buffer layers it reads when --gbuffer is given (motion always; EMA also depth and id).
  std::vector<LayerNeed> gbuffer_layers;
  // Its parameters, bound to the fields of `options` (the CLI and the benchmark use them).
  ParamList (*params)(FilterOptions& options);
  std::unique_ptr<FrameFilter> (*create)(const FilterOptions& options);
};

// The registry, in the order of the docs and --help.
const std::vector<FilterMethod>& filter_methods();
// The method called `name`, or nullptr.
const FilterMethod* find_filter_method(std::string_view name);
// "phlm | taa | ema | fxaa" (for help texts).
std::string filter_method_names();

// The runner stage of filter-phlm (temporal/io/runner.h): selects the layer's channels of each frame, feeds the
// method with the frame's motion (and depth and ids), times it and saves / resumes its state. Usage error for an
// unknown method or invalid parameters.
Expected<std::unique_ptr<FrameStage>> make_filter_stage(const FilterOptions& options);

}  // namespace temporal
