// Parallel per-pixel loops (oneTBB). Work is split into bands of rows; the body receives a half-open row
// range and runs a plain inner loop over x that the compiler can vectorise.
#pragma once

#include <cstddef>
#include <memory>
#include <vector>

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

namespace temporal {

// Limits the threads used by every parallel loop while it lives. 0 means every core.
class ThreadLimit {
 public:
  explicit ThreadLimit(int threads);
  ~ThreadLimit();
  ThreadLimit(const ThreadLimit&) = delete;
  ThreadLimit& operator=(const ThreadLimit&) = delete;

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

// Threads a parallel loop may use now.
int max_threads();

// Threads a parallel loop started here can run on: max_threads(), at most the current task arena's concurrency.
int parallel_threads();

// Rows per chunk for a pass that gives each parallel task a chunk of `rows` rows and pays a fixed cost at every
// chunk's edges (herzog's boundary rows, drobot's band edges): `preferred` rows, the size that keeps that cost a
// small share, unless that leaves fewer chunks than threads the task arena can run (min of the arena's concurrency
// and ThreadLimit), then fewer rows, down to `smallest`; rounded up to a multiple of `align`. With 8 chunks of 64
// rows, 16 cores would leave half of them idle. One chunk per thread, not more: smaller chunks move more rows to
// the edges. (Measured on one CPU, where the time is the work: herzog at 1280x1024 23.0-25.6 ms with chunks of 64
// gradient rows, 20.6-27.2 with 32, 23.4-26.0 with 16; drobot 12.9-14.4 ms with bands of 32 cache rows, 10.8-13.8
// with 16: no cost above this VM's noise.)
int rows_per_chunk(int rows, int preferred, int smallest, int align = 1);

// The boundaries of the chunks of [0, rows) for tasks that take them in order from a shared counter: `bounds` gets
// 0, the end of each chunk, ..., rows. On one thread every chunk has rows_per_chunk's size; on several they shrink
// towards the end (guided self-scheduling: the rows left / (twice the threads), rounded up to `align`, at most
// rows_per_chunk's size and at least `smallest`), so that the threads run out of work together instead of one
// finishing its last large chunk alone (herzog's chunks, drobot's wavefront bands; issue 27).
void guided_chunks(int rows, int preferred, int smallest, int align, std::vector<int>& bounds);

// Calls body(y_begin, y_end) for bands of rows in [0, height), in parallel.
template <typename Body>
void parallel_rows(int height, Body&& body, int grain_rows = 4) {
  tbb::parallel_for(tbb::blocked_range<int>(0, height, grain_rows),
                    [&](const tbb::blocked_range<int>& r) { body(r.begin(), r.end()); });
}

// Calls body(begin, end) for chunks of [0, count), in parallel.
template <typename Body>
void parallel_chunks(std::size_t count, Body&& body, std::size_t grain = 4096) {
  tbb::parallel_for(tbb::blocked_range<std::size_t>(0, count, grain),
                    [&](const tbb::blocked_range<std::size_t>& r) { body(r.begin(), r.end()); });
}

}  // namespace temporal
