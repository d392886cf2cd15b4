#include "mipraster/core/thread_pool.hpp"

#include <chrono>
#include <stdexcept>
#include <string>

#include <unistd.h>

#include "mipraster/core/constants.hpp"

namespace mipraster {

int resolve_thread_count(int requested) {
    if (requested < 0 || requested > kMaxThreads)
        throw std::invalid_argument("threads: expected 0 (all cores) to " + std::to_string(kMaxThreads) +
                                    ", got " + std::to_string(requested));
    if (requested > 0) return requested;
    const unsigned hw = std::thread::hardware_concurrency();
    return hw == 0 ? 1 : static_cast<int>(hw);
}

ThreadPool::ThreadPool(int threads) {
    for (int i = 1; i < threads; ++i) workers_.emplace_back([this] { worker_loop(); });
}

ThreadPool::~ThreadPool() {
    {
        std::lock_guard<std::mutex> lock(mutex_);
        stop_ = true;
    }
    published_generation_.fetch_add(1, std::memory_order_release);  // (ends a worker's spin)
    wake_.notify_all();
    for (auto& t : workers_) t.join();
}

namespace {

// Spins until done() or kPoolSpin has passed (the caller then takes the lock and checks).
template <typename Done>
void spin_until(const Done& done) {
    const auto until = std::chrono::steady_clock::now() + kPoolSpin;
    for (;;) {
        for (int i = 0; i < 32; ++i) {
            if (done()) return;
#if defined(__x86_64__) || defined(__i386__)
            __builtin_ia32_pause();  // (lets the other hyper-thread run, and saves power)
#endif
        }
        if (std::chrono::steady_clock::now() >= until) return;
        std::this_thread::yield();  // a machine with more threads than cores: let one that has work run
    }
}

}  // namespace

void ThreadPool::run_tasks(std::unique_lock<std::mutex>& lock) {
    // Takes indices one at a time under the lock and runs each task unlocked.
    while (next_ < count_) {
        const std::size_t i = next_++;
        const auto* task = task_;
        lock.unlock();
        std::exception_ptr failure;
        try {
            (*task)(i);
        } catch (...) {
            failure = std::current_exception();
        }
        lock.lock();
        if (failure && !error_) {
            error_ = failure;
            finished_ += count_ - next_;  // the tasks not handed out will not run: done with them too
            next_ = count_;               // (stop handing out work)
        }
        if (++finished_ == count_) all_finished_.store(true, std::memory_order_release);
    }
}

void ThreadPool::worker_loop() {
    std::size_t seen = 0;
    std::unique_lock<std::mutex> lock(mutex_);
    for (;;) {
        if (!stop_ && generation_ == seen) {  // the next parallel_for may be microseconds away
            lock.unlock();
            spin_until([&] { return published_generation_.load(std::memory_order_acquire) != seen; });
            lock.lock();
        }
        wake_.wait(lock, [&] { return stop_ || generation_ != seen; });
        if (stop_) return;
        seen = generation_;
        ++busy_workers_;
        run_tasks(lock);
        --busy_workers_;
        done_.notify_all();
    }
}

void ThreadPool::parallel_for(std::size_t count, const std::function<void(std::size_t)>& task) {
    if (count == 0) return;
    if (workers_.empty() || count == 1) {
        for (std::size_t i = 0; i < count; ++i) task(i);
        return;
    }
    std::unique_lock<std::mutex> lock(mutex_);
    task_ = &task;
    count_ = count;
    next_ = 0;
    finished_ = 0;
    error_ = nullptr;
    ++generation_;
    all_finished_.store(false, std::memory_order_relaxed);
    published_generation_.store(generation_, std::memory_order_release);
    wake_.notify_all();
    run_tasks(lock);
    if (finished_ != count_) {  // a worker runs the last tasks: watch for them before sleeping
        lock.unlock();
        spin_until([&] { return all_finished_.load(std::memory_order_acquire); });
        lock.lock();
    }
    done_.wait(lock, [&] { return finished_ == count_ && busy_workers_ == 0; });
    task_ = nullptr;
    if (error_) std::rethrow_exception(error_);
}

namespace {

constexpr std::size_t kMostIdlePools = 4;

struct IdlePools {
    std::mutex mutex;
    std::vector<ThreadPool*> pools;
    pid_t pid = getpid();  // the process whose threads the pools hold
    ~IdlePools() {
        if (pid == getpid())
            for (ThreadPool* p : pools) delete p;
    }
};

IdlePools& idle_pools() {
    static IdlePools idle;
    return idle;
}

}  // namespace

void ReturnToIdle::operator()(ThreadPool* pool) const noexcept {
    IdlePools& idle = idle_pools();
    {
        std::lock_guard<std::mutex> lock(idle.mutex);
        if (idle.pid == getpid() && idle.pools.size() < kMostIdlePools) {
            try {
                idle.pools.push_back(pool);
                return;
            } catch (...) {  // (no room: delete it instead)
            }
        }
    }
    delete pool;
}

LeasedPool lease_thread_pool(int threads) {
    IdlePools& idle = idle_pools();
    {
        std::lock_guard<std::mutex> lock(idle.mutex);
        if (idle.pid != getpid()) {  // a forked child: those workers are not here (left undeleted)
            idle.pools.clear();
            idle.pid = getpid();
        }
        for (auto it = idle.pools.begin(); it != idle.pools.end(); ++it)
            if ((*it)->size() == threads) {
                ThreadPool* pool = *it;
                idle.pools.erase(it);
                return LeasedPool(pool);
            }
    }
    return LeasedPool(new ThreadPool(threads));
}

}  // namespace mipraster
