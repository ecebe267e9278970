/*
 * facyl: fast cylinder detection for PCL.
 * The helper threads of facyl::parallelFor (parallel.h).
 */
#include <facyl/features/parallel.h>

#include <pthread.h>

#include <cstdio>
#include <deque>
#include <system_error>

namespace facyl {
namespace detail {
namespace {

/** Threads that sleep on a condition variable until a job is offered. Never destroyed (a
 * helper may still be waiting when static objects are destroyed at exit). */
class HelperPool {
public:
  void offer(HelperJob& job, int helpers)
  {
    std::unique_lock<std::mutex> lock(mutex_);
    job.wanted = helpers;
    jobs_.push_back(&job);
    pending_ += helpers;
    // Idle helpers (some may be woken for other jobs already) against the helpers wanted.
    while (static_cast<int>(threads_.size()) - busy_ < pending_ && threads_.size() < kMaxThreads) {
      try {
        threads_.emplace_back([this] { serve(); });
      }
      catch (const std::system_error&) { // no more threads: the caller does the work
        break;
      }
    }
    lock.unlock();
    for (int i = 0; i < helpers; ++i)
      wake_.notify_one();
  }

  void withdraw(HelperJob& job)
  {
    std::unique_lock<std::mutex> lock(mutex_);
    if (job.wanted > 0) {
      const auto it = std::find(jobs_.begin(), jobs_.end(), &job);
      if (it != jobs_.end())
        jobs_.erase(it);
      pending_ -= job.wanted;
      job.wanted = 0;
    }
    job.done.wait(lock, [&] { return job.active == 0; });
  }

private:
  static constexpr std::size_t kMaxThreads = 256;

  void serve()
  {
    pthread_setname_np(pthread_self(), "facyl-helper"); // as top and gdb show it
    std::unique_lock<std::mutex> lock(mutex_);
    for (;;) {
      wake_.wait(lock, [&] { return !jobs_.empty(); });
      HelperJob& job = *jobs_.front();
      const int worker = job.next_worker++;
      --pending_;
      if (--job.wanted == 0)
        jobs_.pop_front();
      ++job.active;
      ++busy_;
      lock.unlock();
      job.run(job.context, worker); // does not throw (parallelForWorkers catches)
      lock.lock();
      --busy_;
      if (--job.active == 0)
        job.done.notify_all(); // under the lock: the job outlives this call
    }
  }

  std::mutex mutex_;
  std::condition_variable wake_;
  std::deque<HelperJob*> jobs_; ///< offered, still wanting helpers
  std::vector<std::thread> threads_;
  int pending_{0}; ///< helpers wanted by the offered jobs
  int busy_{0};    ///< helpers inside a job
};

HelperPool* pool_instance{nullptr};
std::once_flag pool_once;

void
startAfresh()
{
  pool_instance = new HelperPool; // a forked child has none of its parent's threads
}

HelperPool&
pool()
{
  std::call_once(pool_once, [] {
    startAfresh();
    pthread_atfork(nullptr, nullptr, startAfresh);
  });
  return *pool_instance;
}

} // namespace

void
offer(HelperJob& job, int helpers)
{
  pool().offer(job, helpers);
}

void
withdraw(HelperJob& job)
{
  pool().withdraw(job);
}

} // namespace detail

int
runnableTasks()
{
  // "0.52 0.58 0.59 3/812 12345": the fourth field is runnable / all tasks.
  std::FILE* f = std::fopen("/proc/loadavg", "r");
  if (!f)
    return -1;
  double a, b, c;
  int running = -1, all = 0;
  const int read = std::fscanf(f, "%lf %lf %lf %d/%d", &a, &b, &c, &running, &all);
  std::fclose(f);
  return read == 5 && running > 0 ? running : -1;
}

int
threadsForIdleCores(int threads, int running, int cores)
{
  const int t = threadCount(threads);
  return t > 1 && (running < 0 || running + (t - 1) <= cores) ? t : 1;
}

int
threadsForIdleCores(int threads)
{
  return threadCount(threads) > 1 ? threadsForIdleCores(threads, runnableTasks(), threadCount(0))
                                  : 1;
}

} // namespace facyl
