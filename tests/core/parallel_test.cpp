// temporal::guided_chunks: the chunk boundaries herzog's chunks and drobot's wavefront bands are taken in, by thread
// count. Values computed by hand from the rule in core/parallel.h (rows_per_chunk's size on one thread; on n threads
// the rows left / 2n, rounded up to the alignment, clamped to [smallest, that size]).
#include "temporal/core/parallel.h"

#include <gtest/gtest.h>
#include <tbb/task_arena.h>

#include <vector>

namespace {

std::vector<int> chunks(int threads, int rows, int preferred, int smallest, int align) {
  std::vector<int> bounds;
  // parallel_threads() is the arena's concurrency capped by TBB's allowed parallelism, which defaults to the machine's
  // cores: raised here so that the test gives the same bounds on a 2-core machine as on a 16-core one.
  const temporal::ThreadLimit limit(threads);
  tbb::task_arena(threads).execute([&] { temporal::guided_chunks(rows, preferred, smallest, align, bounds); });
  return bounds;
}

TEST(GuidedChunks, OneThreadTakesEqualChunks) {
  // rows_per_chunk(69, 32, 16) on one thread: 32.
  EXPECT_EQ(chunks(1, 69, 32, 16, 1), (std::vector<int>{0, 32, 64, 69}));
}

TEST(GuidedChunks, SeveralThreadsShrinkTowardsTheEnd) {
  // drobot's bands at 1280x1024, k = 4 (256 cache rows), two threads: (256 + 3) / 4 = 64 -> 32 five times, then
  // 96 / 4 = 24, 72 / 4 = 18, 54 / 4 -> 14 -> 16 three times, the last 6.
  EXPECT_EQ(chunks(2, 256, 32, 16, 1), (std::vector<int>{0, 32, 64, 96, 128, 160, 184, 202, 218, 234, 250, 256}));
  // The reference test's 69 cache rows: two threads 18, 16, 16, 16, 3; three threads (rows_per_chunk 23) 16 x 4, 5.
  EXPECT_EQ(chunks(2, 69, 32, 16, 1), (std::vector<int>{0, 18, 34, 50, 66, 69}));
  EXPECT_EQ(chunks(3, 69, 32, 16, 1), (std::vector<int>{0, 16, 32, 48, 64, 69}));
}

TEST(GuidedChunks, SizesRoundUpToTheAlignment) {
  // herzog's 138 gradient rows in chunks aligned to 4 (two pyramid levels), two threads: 141 / 4 = 35 -> 36,
  // 105 / 4 = 26 -> 28, 77 / 4 = 19 -> 20, 57 / 4 = 14 -> 16, then 16, 16 and the last 6.
  EXPECT_EQ(chunks(2, 138, 64, 16, 4), (std::vector<int>{0, 36, 64, 84, 100, 116, 132, 138}));
}

}  // namespace
