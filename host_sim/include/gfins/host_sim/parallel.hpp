// Runs independent jobs (Monte-Carlo runs, covariance propagations) on several threads with a
// result that does not depend on the thread count: bit for bit what one thread computes.
//
// Two rules make that hold, and the callers keep both:
//   - job k depends on k (and on read-only inputs) only: its random streams are seeded from
//     (seed, k), never from a generator shared between jobs or from the thread that runs it;
//   - results are combined in index order: consume(0, r0), consume(1, r1), ... on the calling
//     thread, whatever order the jobs finish in. Floating-point addition is not associative, so
//     a sum taken in completion order would change in its last bits from run to run.
//
// Memory stays bounded: at most 2 × jobs results wait for their turn (a job that would run
// further ahead waits), so a run of 100,000 seeds holds a few results, not all of them.
#pragma once

#include <algorithm>
#include <condition_variable>
#include <cstddef>
#include <exception>
#include <mutex>
#include <optional>
#include <thread>
#include <type_traits>
#include <utility>
#include <vector>

namespace gfins::sim {

/// The thread count `jobs = 0` stands for: std::thread::hardware_concurrency(), at least 1.
inline std::size_t default_jobs() {
  return std::max<std::size_t>(1, std::thread::hardware_concurrency());
}

/// Calls produce(k) for k = 0 .. n − 1 on up to `jobs` worker threads (0: default_jobs()) and
/// consume(k, result) on the calling thread in increasing k. consume returns false to stop: no
/// further job starts, the running ones finish and their results are dropped. An exception from
/// produce(k) is rethrown on the calling thread when k's turn comes (after the workers have
/// stopped), one from consume at once; either way every worker is joined first.
///
/// With jobs = 1 (or n ≤ 1) no thread is started: produce and consume alternate on the caller.
/// produce must be safe to call concurrently for different k; consume is never concurrent.
template <typename Produce, typename Consume>
void ordered_parallel_for(std::size_t n, std::size_t jobs, Produce&& produce, Consume&& consume) {
  using R = std::decay_t<std::invoke_result_t<Produce&, std::size_t>>;
  if (jobs == 0) jobs = default_jobs();
  jobs = std::min(jobs, n);
  if (jobs <= 1) {
    for (std::size_t k = 0; k < n; ++k) {
      if (!consume(k, produce(k))) return;
    }
    return;
  }

  // Slot k % window holds job k's result from its end until consume takes it. A worker claims k
  // only when k < consumed + window, so the slot it will fill has been emptied.
  const std::size_t window = 2 * jobs;
  struct Slot {
    bool ready = false;
    std::optional<R> value;
    std::exception_ptr error;
  };
  std::vector<Slot> slots(window);
  std::mutex mutex;
  std::condition_variable changed;
  std::size_t next_claim = 0;
  std::size_t consumed = 0;
  bool stop = false;

  const auto worker = [&] {
    for (;;) {
      std::size_t k = 0;
      {
        std::unique_lock lock(mutex);
        changed.wait(lock,
                     [&] { return stop || next_claim >= n || next_claim < consumed + window; });
        if (stop || next_claim >= n) return;
        k = next_claim++;
      }
      std::optional<R> value;
      std::exception_ptr error;
      try {
        value.emplace(produce(k));
      } catch (...) {
        error = std::current_exception();
      }
      {
        const std::lock_guard lock(mutex);
        Slot& s = slots[k % window];
        s.value = std::move(value);
        s.error = error;
        s.ready = true;
      }
      changed.notify_all();
    }
  };

  // Joins on every way out (normal end, stop, exception, a thread that failed to start).
  struct Joiner {
    std::vector<std::thread> threads;
    std::mutex& mutex;
    std::condition_variable& changed;
    bool& stop;
    ~Joiner() {
      {
        const std::lock_guard lock(mutex);
        stop = true;
      }
      changed.notify_all();
      for (auto& t : threads) t.join();
    }
  } joiner{{}, mutex, changed, stop};
  joiner.threads.reserve(jobs);
  for (std::size_t i = 0; i < jobs; ++i) joiner.threads.emplace_back(worker);

  for (std::size_t k = 0; k < n; ++k) {
    Slot taken;
    {
      std::unique_lock lock(mutex);
      Slot& s = slots[k % window];
      changed.wait(lock, [&] { return s.ready; });
      taken = std::move(s);
      s = Slot{};
      ++consumed;
    }
    changed.notify_all();
    if (taken.error) std::rethrow_exception(taken.error);  // the Joiner stops the workers
    if (!consume(k, std::move(*taken.value))) return;
  }
}

}  // namespace gfins::sim
