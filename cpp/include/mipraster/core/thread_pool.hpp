#pragma once
// A small persistent thread pool: parallel_for hands out task indices; callers keep results
// per task so output never depends on how many threads ran.
#include <atomic>
#include <condition_variable>
#include <cstddef>
#include <functional>
#include <memory>
#include <mutex>
#include <thread>
#include <vector>

namespace mipraster {

class ThreadPool {
public:
    /// `threads` workers in total, the calling thread included (1 = run everything inline).
    explicit ThreadPool(int threads);
    ~ThreadPool();
    ThreadPool(const ThreadPool&) = delete;
    ThreadPool& operator=(const ThreadPool&) = delete;

    int size() const { return static_cast<int>(workers_.size()) + 1; }

    /// Calls task(i) for every i in [0, count), on any thread; returns when all are done.
    /// The first exception thrown by a task is rethrown here.
    void parallel_for(std::size_t count, const std::function<void(std::size_t)>& task);

private:
    void worker_loop();
    void run_tasks(std::unique_lock<std::mutex>& lock);

    std::vector<std::thread> workers_;
    std::mutex mutex_;
    std::condition_variable wake_, done_;
    const std::function<void(std::size_t)>* task_ = nullptr;
    std::size_t count_ = 0, next_ = 0, finished_ = 0;
    std::size_t generation_ = 0;
    // generation_ and "every task finished", readable without the lock: a worker that has just run
    // out of work, and a caller that waits for the last task, watch them for a short while before
    // they sleep on the condition variables (see kPoolSpin).
    std::atomic<std::size_t> published_generation_{0};
    std::atomic<bool> all_finished_{true};
    int busy_workers_ = 0;
    bool stop_ = false;
    std::exception_ptr error_;
};

/// Number of threads to use for a request of `requested` (0 = all hardware threads).
int resolve_thread_count(int requested);

/// Gives a leased pool back to the idle ones (or deletes it when enough are idle).
struct ReturnToIdle {
    void operator()(ThreadPool* pool) const noexcept;
};
using LeasedPool = std::unique_ptr<ThreadPool, ReturnToIdle>;

/// A pool of `threads` threads for one piece of work: an idle one of that size when there is one,
/// else a new one. Creating and joining a worker costs ~50–190 µs, a few per cent of a small
/// frame, so renders keep their pools idle (waiting on a condition variable) for the next render.
/// Pools left from before a fork() are not reused in the child, whose workers they do not have.
LeasedPool lease_thread_pool(int threads);

}  // namespace mipraster
