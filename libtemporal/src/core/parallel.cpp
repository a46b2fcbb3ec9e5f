#include "temporal/core/parallel.h"

#include <tbb/global_control.h>
#include <tbb/info.h>
#include <tbb/task_arena.h>

#include <algorithm>

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

int parallel_threads() { return std::max(1, std::min(max_threads(), tbb::this_task_arena::max_concurrency())); }

int rows_per_chunk(int rows, int preferred, int smallest, int align) {
  const int threads = parallel_threads();
  const int wanted = std::clamp((rows + threads - 1) / threads, std::min(smallest, preferred), preferred);
  const int a = std::max(1, align);
  return std::max(a, (wanted + a - 1) / a * a);
}

void guided_chunks(int rows, int preferred, int smallest, int align, std::vector<int>& bounds) {
  const int a = std::max(1, align);
  const int most = rows_per_chunk(rows, preferred, smallest, a);
  const int threads = parallel_threads();
  bounds.assign(1, 0);
  for (int r = 0; r < rows;) {
    int size = most;
    if (threads > 1) {
      const int guided = (rows - r + 2 * threads - 1) / (2 * threads);
      size = std::clamp((guided + a - 1) / a * a, std::min(most, smallest), most);
    }
    r = std::min(rows, r + size);
    bounds.push_back(r);
  }
}

}  // namespace temporal
