#include "temporal/core/parallel.h"

#include <tbb/global_control.h>
#include <tbb/info.h>

namespace temporal {

struct ThreadLimit::Impl {
  tbb::global_control control;
};

ThreadLimit::ThreadLimit(int threads)
    : impl_(threads > 0 ? new Impl{tbb::global_control(tbb::global_control::max_allowed_parallelism, std::size_t(threads))}
                        : nullptr) {}

ThreadLimit::~ThreadLimit() = default;

int max_threads() {
  return int(tbb::global_control::active_value(tbb::global_control::max_allowed_parallelism));
}

}  // namespace temporal
