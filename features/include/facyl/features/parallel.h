/*
 * facyl: fast cylinder detection for PCL.
 * A parallel loop that never spins: blocks of a range run on the calling thread and on a few
 * helper threads that sleep in the kernel while there is no work (a condition variable, never
 * a busy wait). facyl runs beside other processes on few cores; OpenMP's default wait policy
 * busy-waits there and multiplies the time of short parallel regions. The helpers are started
 * on first use and kept, asleep, for the process's life: waking a sleeping helper costs far
 * less than starting and joining threads for every loop. Both costs are measured in
 * docs/speed.md ("Parallel loops on sleeping helpers").
 */
#pragma once

#include <algorithm>
#include <atomic>
#include <condition_variable>
#include <cstddef>
#include <exception>
#include <mutex>
#include <thread>
#include <vector>

namespace facyl {

/** \brief The threads a setting asks for: \a threads, or (0 or less) the hardware's
 * concurrency; at least 1. */
inline int
threadCount(int threads)
{
  return std::max(threads > 0 ? threads : static_cast<int>(std::thread::hardware_concurrency()), 1);
}

/** \brief Threads a parallel loop over \a n items uses: threadCount(\a threads), at most one
 * per \a grain items, at least 1. */
inline int
parallelWorkers(std::size_t n, int threads, std::size_t grain)
{
  const int t = threadCount(threads);
  const std::size_t blocks =
    (n + std::max<std::size_t>(grain, 1) - 1) / std::max<std::size_t>(grain, 1);
  return static_cast<int>(
    std::max<std::size_t>(1, std::min<std::size_t>(blocks, static_cast<std::size_t>(t))));
}

/** \brief Tasks ready to run on the machine now, this thread included (the kernel's count of
 * runnable tasks, /proc/loadavg); -1 where the system does not tell. */
int runnableTasks();

/** \brief The threads for short loops that a sleeping helper would stall when it is preempted
 * (a loop waits for its slowest block): threadCount(\a threads) while the helpers it adds find
 * idle cores (runnableTasks() plus the helpers at most the hardware's concurrency, or the count
 * unknown), else 1. Beside busy processes a helper gets a share of a core, and the loop then
 * waits for a time slice of the scheduler rather than for its work. */
int threadsForIdleCores(int threads);

/** \brief threadsForIdleCores's rule on given counts: threadCount(\a threads) when \a running
 * (runnable tasks, the caller included; negative: unknown) plus the helpers is at most
 * \a cores, else 1. */
int threadsForIdleCores(int threads, int running, int cores);

namespace detail {

/** \brief A parallel loop's work offered to the helper threads: each helper that takes it calls
 * run(context, worker) once, with its own worker number in [1, helpers]. */
struct HelperJob {
  void (*run)(void* context, int worker){nullptr};
  void* context{nullptr};
  int wanted{0};                ///< helpers still wanted (guarded by the pool's mutex)
  int next_worker{1};           ///< the number the next helper gets
  int active{0};                ///< helpers inside run
  std::condition_variable done; ///< signalled when active drops to 0
};

/** \brief Offers \a job to \a helpers sleeping helper threads (started if fewer are idle) and
 * returns at once. Thread-safe; callable from within a job (nested loops). */
void offer(HelperJob& job, int helpers);

/** \brief Takes \a job back: no helper starts it any more; returns when every helper that
 * started it has returned from run. */
void withdraw(HelperJob& job);

} // namespace detail

/** \brief Calls \a body(begin, end, worker) on blocks of at most \a grain items covering
 * [0, n), on parallelWorkers(n, threads, grain) threads (the caller's among them); blocks are
 * taken in order by whichever thread is free, and \a worker (in [0, parallelWorkers(...)))
 * names the thread that runs the block, so that each thread can use state of its own. Returns
 * when all blocks are done; the first exception a block throws is rethrown here. \a body must
 * only write what its block or its worker owns: the result then does not depend on the number
 * of threads. */
template <typename Body>
void
parallelForWorkers(std::size_t n, int threads, std::size_t grain, Body&& body)
{
  grain = std::max<std::size_t>(grain, 1);
  const int workers = parallelWorkers(n, threads, grain);
  if (workers <= 1) {
    for (std::size_t b = 0; b < n; b += grain)
      body(b, std::min(n, b + grain), 0);
    return;
  }
  std::atomic<std::size_t> next{0};
  std::exception_ptr failure;
  std::mutex failure_mutex;
  auto work = [&](int worker) {
    try {
      for (std::size_t b = next.fetch_add(grain); b < n; b = next.fetch_add(grain))
        body(b, std::min(n, b + grain), worker);
    }
    catch (...) {
      const std::lock_guard<std::mutex> lock(failure_mutex);
      if (!failure)
        failure = std::current_exception();
      next = n; // the others stop after their block
    }
  };
  detail::HelperJob job;
  job.context = &work;
  job.run = [](void* context, int worker) { (*static_cast<decltype(work)*>(context))(worker); };
  detail::offer(job, workers - 1);
  work(0);
  detail::withdraw(job); // returns when the helpers that took part are done
  if (failure)
    std::rethrow_exception(failure);
}

/** \brief Calls \a body(begin, end) on blocks of at most \a grain items covering [0, n), as
 * parallelForWorkers does. \a body must only write what its block owns: the result then does
 * not depend on the number of threads. */
template <typename Body>
void
parallelFor(std::size_t n, int threads, std::size_t grain, Body&& body)
{
  parallelForWorkers(n, threads, grain,
                     [&body](std::size_t begin, std::size_t end, int) { body(begin, end); });
}

} // namespace facyl
