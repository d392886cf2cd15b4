// The thread pool (thread_pool.hpp): every index of every parallel_for runs exactly once and is
// finished when the call returns, for calls back to back and after the workers have gone to sleep;
// a task's exception reaches the caller and leaves the pool usable; pools are leased again.
#include <gtest/gtest.h>

#include <atomic>
#include <chrono>
#include <cstddef>
#include <stdexcept>
#include <thread>
#include <vector>

#include "mipraster/core/thread_pool.hpp"

namespace {

namespace mr = mipraster;

// Runs `calls` parallel_for calls of varying size back to back, pausing `pause` before some of
// them, and checks each index ran once and had finished by the time its call returned.
void expect_each_index_once(mr::ThreadPool& pool, int calls, std::chrono::microseconds pause) {
    for (int call = 0; call < calls; ++call) {
        const std::size_t count = 1 + static_cast<std::size_t>(call * 7 % 23);
        std::vector<std::atomic<int>> runs(count);
        for (auto& r : runs) r = 0;
        if (call % 5 == 4) std::this_thread::sleep_for(pause);
        pool.parallel_for(count, [&](std::size_t i) {
            if (i % 3 == 0) std::this_thread::sleep_for(std::chrono::microseconds(20));  // uneven tasks
            runs[i].fetch_add(1);
        });
        for (std::size_t i = 0; i < count; ++i) ASSERT_EQ(runs[i].load(), 1) << "call " << call << " index " << i;
    }
}

TEST(ThreadPool, EveryIndexRunsOnceInCallsBackToBackAndAfterSleeps) {
    for (int threads : {1, 2, 3, 8}) {
        SCOPED_TRACE(threads);
        mr::ThreadPool pool(threads);
        EXPECT_EQ(pool.size(), threads);
        expect_each_index_once(pool, 300, std::chrono::microseconds(0));     // back to back
        expect_each_index_once(pool, 20, std::chrono::microseconds(3000));  // workers asleep between
    }
}

TEST(ThreadPool, AllThreadsTakePartInLongWork) {
    mr::ThreadPool pool(2);
    std::vector<std::thread::id> ran_on(64);
    pool.parallel_for(ran_on.size(), [&](std::size_t i) {
        std::this_thread::sleep_for(std::chrono::milliseconds(1));
        ran_on[i] = std::this_thread::get_id();
    });
    std::size_t on_caller = 0;
    for (const auto& id : ran_on) on_caller += id == std::this_thread::get_id();
    EXPECT_GT(on_caller, 0u);
    EXPECT_LT(on_caller, ran_on.size()) << "the worker ran none of 64 one-millisecond tasks";
}

TEST(ThreadPool, ATaskExceptionReachesTheCallerAndThePoolStaysUsable) {
    mr::ThreadPool pool(2);
    for (int round = 0; round < 20; ++round) {
        EXPECT_THROW(pool.parallel_for(50,
                                       [&](std::size_t i) {
                                           if (i == static_cast<std::size_t>(round)) throw std::runtime_error("task");
                                       }),
                     std::runtime_error);
        expect_each_index_once(pool, 5, std::chrono::microseconds(0));
    }
}

TEST(ThreadPool, ALeasedPoolReturnsToTheIdleOnesAndIsLeasedAgain) {
    mr::ThreadPool* first;
    {
        const mr::LeasedPool a = mr::lease_thread_pool(3);
        first = a.get();
        EXPECT_EQ(a->size(), 3);
    }
    const mr::LeasedPool b = mr::lease_thread_pool(3);
    EXPECT_EQ(b.get(), first);
    const mr::LeasedPool c = mr::lease_thread_pool(3);  // the idle one is taken: a new one
    EXPECT_NE(c.get(), first);
    expect_each_index_once(*c, 10, std::chrono::microseconds(0));
}

}  // namespace
