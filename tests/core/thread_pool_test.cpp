#include "pegasus/parallel/thread_pool.hpp"

#include <gtest/gtest.h>

#include <atomic>
#include <cmath>
#include <numeric>
#include <stdexcept>
#include <vector>

#include "pegasus/core/error.hpp"
#include "pegasus/random/counter_rng.hpp"

namespace pegasus {

TEST(ThreadPool, RunsEveryIndexExactlyOnceForAnyThreadCount) {
  for (int threads : {1, 2, 3, 5}) {
    ThreadPool pool(threads);
    for (std::size_t n : {0u, 1u, 7u, 1000u}) {
      std::vector<std::atomic<int>> hits(n);
      pool.parallel_for(
          n, [&](std::size_t i) { hits[i].fetch_add(1); }, 3);
      for (std::size_t i = 0; i < n; ++i) EXPECT_EQ(hits[i].load(), 1) << "threads=" << threads;
    }
  }
}

// Many short calls back to back, each with its own size and grain: a worker that wakes late for one call
// must never run a chunk of the next with the first one's size or grain (each index exactly once, in every
// call). The calls are shorter than a thread's wake-up, which is when workers are late.
TEST(ThreadPool, BackToBackCallsOfOtherShapesEachRunEveryIndexOnce) {
  for (int threads : {2, 3, 4}) {
    ThreadPool pool(threads);
    std::vector<std::atomic<int>> hits(64);
    for (int call = 0; call < 4000; ++call) {
      const std::size_t n = 2 + static_cast<std::size_t>(call * 7 % 61);
      const std::size_t grain = 1 + static_cast<std::size_t>(call % 5);
      for (std::size_t i = 0; i < n; ++i) hits[i].store(0, std::memory_order_relaxed);
      pool.parallel_for_chunks(n, grain, [&](std::size_t begin, std::size_t end) {
        for (std::size_t i = begin; i < end; ++i) hits[i].fetch_add(1, std::memory_order_relaxed);
      });
      for (std::size_t i = 0; i < n; ++i)
        ASSERT_EQ(hits[i].load(), 1) << "threads " << threads << " call " << call << " index " << i;
    }
  }
}

TEST(ThreadPool, RethrowsTheExceptionOfAFailingChunk) {
  ThreadPool pool(2);
  EXPECT_THROW(pool.parallel_for(100,
                                 [](std::size_t i) {
                                   if (i == 57) throw std::runtime_error("boom");
                                 }),
               std::runtime_error);
  // The pool stays usable afterwards.
  std::atomic<int> sum{0};
  pool.parallel_for(10, [&](std::size_t i) { sum += static_cast<int>(i); });
  EXPECT_EQ(sum.load(), 45);
}

TEST(ThreadPool, RejectsFewerThanOneThread) { EXPECT_THROW(ThreadPool(0), InputError); }

TEST(CounterRng, IsAPureFunctionOfSeedAndCounter) {
  CounterRng a(42), b(42), c(43);
  const auto x = a.uniform2(RngDomain::kStepNoise, 3, 7, 0);
  const auto y = b.uniform2(RngDomain::kStepNoise, 3, 7, 0);
  const auto z = c.uniform2(RngDomain::kStepNoise, 3, 7, 0);
  const auto w = a.uniform2(RngDomain::kInitialNoise, 3, 7, 0);
  EXPECT_EQ(x, y);
  EXPECT_NE(x, z);
  EXPECT_NE(x, w);
}

TEST(CounterRng, UniformsAreInsideTheOpenUnitIntervalWithTheRightMoments) {
  CounterRng rng(7);
  double sum = 0, sum2 = 0;
  const int n = 200000;
  for (int i = 0; i < n / 2; ++i) {
    for (double u : rng.uniform2(RngDomain::kStream, static_cast<std::uint32_t>(i), 0, 0)) {
      ASSERT_GT(u, 0.0);
      ASSERT_LT(u, 1.0);
      sum += u;
      sum2 += u * u;
    }
  }
  const double mean = sum / n, var = sum2 / n - mean * mean;
  EXPECT_NEAR(mean, 0.5, 4 * std::sqrt(1.0 / 12 / n));
  EXPECT_NEAR(var, 1.0 / 12, 0.002);
}

TEST(UniformStream, ResumingAtAPositionContinuesTheSameSequence) {
  UniformStream s(9, 4);
  std::vector<double> first;
  for (int i = 0; i < 11; ++i) first.push_back(s.next());
  UniformStream resumed(9, 4, 5);
  for (int i = 5; i < 11; ++i) EXPECT_EQ(resumed.next(), first[i]);
}

}  // namespace pegasus
