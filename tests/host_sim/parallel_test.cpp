// ordered_parallel_for (host_sim/parallel.hpp): every job once, results handed over in index
// order whatever order the jobs finish in, a bounded number of results waiting, stop and
// exceptions at their index. The oracle is the index sequence 0, 1, ..., n − 1 itself.
#include "gfins/host_sim/parallel.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <atomic>
#include <future>
#include <mutex>
#include <stdexcept>
#include <string>
#include <thread>
#include <vector>

namespace gfins::sim {
namespace {

constexpr std::size_t kJobs[] = {1, 2, 7};
constexpr std::size_t kN = 50;

TEST(OrderedParallelFor, EveryJobOnceAndResultsInIndexOrder) {
  for (const std::size_t jobs : kJobs) {
    SCOPED_TRACE("jobs " + std::to_string(jobs));
    // Given n jobs whose result is their index squared,
    std::vector<std::atomic<int>> produced(kN);
    std::vector<std::size_t> order;
    // when they run on `jobs` threads,
    ordered_parallel_for(
        kN, jobs,
        [&](std::size_t k) {
          ++produced[k];
          return k * k;
        },
        [&](std::size_t k, std::size_t r) {
          EXPECT_EQ(r, k * k);
          order.push_back(k);
          return true;
        });
    // then each ran once and the results came in the order 0, 1, ..., n − 1.
    for (std::size_t k = 0; k < kN; ++k) EXPECT_EQ(produced[k].load(), 1) << "job " << k;
    ASSERT_EQ(order.size(), kN);
    for (std::size_t k = 0; k < kN; ++k) EXPECT_EQ(order[k], k);
  }
}

TEST(OrderedParallelFor, AJobThatFinishesFirstWaitsForItsTurn) {
  // Given job 0 that cannot finish before job 1 has (so the completion order is 1, 0 for sure),
  std::promise<void> one_done;
  std::shared_future<void> one_done_f = one_done.get_future().share();
  std::vector<std::size_t> order;
  ordered_parallel_for(
      2, 2,
      [&](std::size_t k) {
        if (k == 0) one_done_f.wait();
        if (k == 1) one_done.set_value();
        return k;
      },
      [&](std::size_t k, std::size_t) {
        order.push_back(k);
        return true;
      });
  // then the results are still handed over as 0, 1.
  EXPECT_EQ(order, (std::vector<std::size_t>{0, 1}));
}

TEST(OrderedParallelFor, AtMostTwiceJobsResultsWaitAhead) {
  for (const std::size_t jobs : kJobs) {
    SCOPED_TRACE("jobs " + std::to_string(jobs));
    // Given a slow consumer,
    std::atomic<std::size_t> started{0};
    std::size_t worst_ahead = 0;
    ordered_parallel_for(
        kN, jobs,
        [&](std::size_t k) {
          ++started;
          return k;
        },
        [&](std::size_t k, std::size_t) {
          // When result k is handed over, the jobs started beyond k are the window at most
          // (2 × jobs; one thread: none).
          const std::size_t ahead = started.load() - (k + 1);
          worst_ahead = std::max(worst_ahead, ahead);
          std::this_thread::yield();
          return true;
        });
    EXPECT_LE(worst_ahead, jobs == 1 ? 0 : 2 * jobs);
  }
}

TEST(OrderedParallelFor, ConsumeFalseStopsTheRest) {
  for (const std::size_t jobs : kJobs) {
    SCOPED_TRACE("jobs " + std::to_string(jobs));
    std::atomic<std::size_t> started{0};
    std::vector<std::size_t> order;
    constexpr std::size_t kStopAt = 3;
    ordered_parallel_for(
        kN, jobs,
        [&](std::size_t k) {
          ++started;
          return k;
        },
        [&](std::size_t k, std::size_t) {
          order.push_back(k);
          return k != kStopAt;
        });
    EXPECT_EQ(order, (std::vector<std::size_t>{0, 1, 2, 3}));
    // No job started beyond the window of the last result taken.
    EXPECT_LE(started.load(), kStopAt + 1 + 2 * jobs);
  }
}

TEST(OrderedParallelFor, TheFirstFailingJobByIndexIsRethrownAtItsTurn) {
  for (const std::size_t jobs : kJobs) {
    SCOPED_TRACE("jobs " + std::to_string(jobs));
    // Given jobs 5 and 2 that throw (5 may well fail first in time),
    std::vector<std::size_t> order;
    std::string what;
    try {
      ordered_parallel_for(
          kN, jobs,
          [&](std::size_t k) {
            if (k == 5 || k == 2) throw std::runtime_error("job " + std::to_string(k));
            return k;
          },
          [&](std::size_t k, std::size_t) {
            order.push_back(k);
            return true;
          });
    } catch (const std::runtime_error& e) {
      what = e.what();
    }
    // then the caller sees job 2's exception after exactly the results before it.
    EXPECT_EQ(what, "job 2");
    EXPECT_EQ(order, (std::vector<std::size_t>{0, 1}));
  }
}

TEST(OrderedParallelFor, AnExceptionFromConsumeJoinsTheWorkersAndPropagates) {
  for (const std::size_t jobs : kJobs) {
    SCOPED_TRACE("jobs " + std::to_string(jobs));
    EXPECT_THROW(ordered_parallel_for(
                     kN, jobs, [](std::size_t k) { return k; },
                     [](std::size_t k, std::size_t) -> bool {
                       if (k == 4) throw std::logic_error("consume");
                       return true;
                     }),
                 std::logic_error);
  }
}

TEST(OrderedParallelFor, ZeroJobsMeansTheHardwareAndZeroItemsRunNothing) {
  EXPECT_GE(default_jobs(), 1u);
  int calls = 0;
  ordered_parallel_for(
      0, 0,
      [&](std::size_t) {
        ++calls;
        return 0;
      },
      [&](std::size_t, int) {
        ++calls;
        return true;
      });
  EXPECT_EQ(calls, 0);
  std::vector<std::size_t> order;
  ordered_parallel_for(
      5, 0, [](std::size_t k) { return k; },
      [&](std::size_t k, std::size_t) {
        order.push_back(k);
        return true;
      });
  EXPECT_EQ(order, (std::vector<std::size_t>{0, 1, 2, 3, 4}));
}

}  // namespace
}  // namespace gfins::sim
