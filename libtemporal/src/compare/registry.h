// What a metric source file (src/compare/metric_<name>.cpp) includes: the registry's types. Each file defines
// `MetricDefinition <name>_metric()` for every metric it holds; registry.cpp declares and lists them in one line
// each. Private to the compare stage.
#pragma once

#include "temporal/compare/comparison.h"
