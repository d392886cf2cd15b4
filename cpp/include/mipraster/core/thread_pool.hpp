#pragma once
// A small persistent thread pool: parallel_for hands out task indices; callers keep results
// per task so output never depends on how many threads ran.
#include <condition_variable>
#include <cstddef>
#include <functional>
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
    int busy_workers_ = 0;
    bool stop_ = false;
    std::exception_ptr error_;
};

/// Number of threads to use for a request of `requested` (0 = all hardware threads).
int resolve_thread_count(int requested);

}  // namespace mipraster
